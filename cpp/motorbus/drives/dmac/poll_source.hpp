// A poll source for DMAC modules on an ASCII line: one READ per field
// (#POSITION, #SPEED, #STATUS...), through a client of its own on the drive's
// LineLink (the link serializes transactions with the Drive's client).  Each
// READ waits the module's turnaround (#LINE_DELAY, 3 ms from the factory), so
// a DMAC line polls at tens of Hz, not kHz.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "motorbus/drives/dmac/client.hpp"
#include "motorbus/poll/source.hpp"

namespace motorbus::dmac {

class PollSource final : public poll::Source {
public:
    // `names`: variable names ("POSITION" or "#POSITION"); #STATUS and #ERROR are
    // read in hex (their bits), the rest in decimal.  InvalidArgument for an
    // unknown name.
    PollSource(std::shared_ptr<serial::LineLink> link, ClientOptions options, std::vector<std::string> names);

    std::size_t columns() const override { return vars_.size(); }
    void read(double* out) override;
    std::string describe() const override;

private:
    Client client_;
    std::vector<Var> vars_;
    std::vector<Radix> radix_;
};

}  // namespace motorbus::dmac
