// EDS/DCF (CiA 306 INI files): import a vendor's description into an
// ObjectDictionary, export the dictionary of any node we serve.
//
//   auto od = load_eds("drive.eds", /*node_id=*/5);     // $NODEID+0x180 -> 0x185
//   auto v = od->at("Identity object.Vendor-ID");
//   std::string text = to_eds(*od);                     // or to_eds(*od, {.dcf = true})
//
// Import is lenient where vendor files are sloppy (case of sections and keys,
// hex/decimal/octal numbers, `$NODEID` on either side of `+`, CompactSubObj
// arrays with their [xxxxName] section, a record whose sub 0 is not UNSIGNED8)
// and strict where it matters: an entry it cannot represent (unknown data
// type, a default that does not fit) is skipped and reported in `warnings`,
// never guessed.
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/canopen/od.hpp"

namespace motorbus::canopen {

struct EdsImportOptions {
    // Node-id for $NODEID; 0 = take [DeviceComissioning] NodeID, else 0.
    std::uint8_t node_id = 0;
    // A DCF's ParameterValue becomes the current value (DefaultValue stays the default).
    bool use_parameter_values = true;
};

struct EdsExportOptions {
    bool dcf = false;  // also write ParameterValue (current values) and [DeviceComissioning]
    std::uint8_t node_id = 0;  // for [DeviceComissioning]; 0 = the dictionary's node_id
};

// Parses EDS/DCF text.  Throws InvalidArgument when the text has no object
// sections at all or a line is not INI; skips (and reports) bad entries.
std::shared_ptr<ObjectDictionary> parse_eds(std::string_view text, const EdsImportOptions& options = {},
                                            std::vector<std::string>* warnings = nullptr);
// The largest EDS/DCF file load_eds reads (16 MiB; real files are a few
// hundred kB).  A bigger file, or an endless one (/dev/zero, a FIFO), is
// refused with InvalidArgument naming the file and the cap; reading stops there.
inline constexpr std::size_t kMaxEdsFileBytes = std::size_t{16} << 20;
// Reads a file (InvalidArgument naming the path if it cannot be read or is
// larger than kMaxEdsFileBytes).
std::shared_ptr<ObjectDictionary> load_eds(const std::string& path, const EdsImportOptions& options = {},
                                           std::vector<std::string>* warnings = nullptr);

std::string to_eds(const ObjectDictionary& od, const EdsExportOptions& options = {});
void save_eds(const ObjectDictionary& od, const std::string& path, const EdsExportOptions& options = {});

// "$NODEID+0x180", "0x180+$NODEID", "384", "0x20010032", "-5", "017" (octal):
// the integer value, or nullopt when it is not an integer expression.
std::optional<std::int64_t> eval_eds_integer(std::string_view expr, std::uint8_t node_id,
                                             bool* uses_node_id = nullptr);

}  // namespace motorbus::canopen
