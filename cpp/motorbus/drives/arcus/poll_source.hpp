// A poll source for DMX-CAN drives on an ASCII line: one query per field
// ("EX", "PS", "MST"...), through a Client of its own on the drive's LineLink
// (the link serializes transactions with the Drive's client; a client of our
// own keeps the counters of the two threads apart).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/poll/source.hpp"

namespace motorbus::arcus {

class PollSource final : public poll::Source {
public:
    // InvalidArgument for no names or a name the protocol cannot query.
    PollSource(std::shared_ptr<serial::LineLink> link, int address, std::vector<std::string> names,
               ClientOptions options = {});

    std::size_t columns() const override { return names_.size(); }
    void read(double* out) override;
    std::string describe() const override;

private:
    Client client_;
    std::vector<std::string> names_;
};

}  // namespace motorbus::arcus
