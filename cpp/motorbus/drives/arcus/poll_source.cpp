#include "motorbus/drives/arcus/poll_source.hpp"

#include <cctype>
#include <cstdio>

#include "motorbus/errors.hpp"

namespace motorbus::arcus {

namespace {
ClientOptions with_address(ClientOptions o, int address) {
    o.address = address;
    return o;
}
}  // namespace

PollSource::PollSource(std::shared_ptr<serial::LineLink> link, int address, std::vector<std::string> names,
                       ClientOptions options)
    : client_(std::move(link), with_address(options, address)), names_(std::move(names)) {
    if (names_.empty()) throw InvalidArgument("arcus poll source: at least one query name (EX, PS, MST...)");
    for (const auto& n : names_) {
        if (n.empty() || n.size() > 8)
            throw InvalidArgument("arcus poll query '" + n + "': a command name of 1 to 8 letters");
        for (unsigned char c : n)
            if (!std::isalnum(c))
                throw InvalidArgument("arcus poll query '" + n + "': letters and digits only (a query, not a command)");
    }
}

void PollSource::read(double* out) {
    for (std::size_t i = 0; i < names_.size(); ++i) out[i] = static_cast<double>(client_.query(names_[i]));
}

std::string PollSource::describe() const {
    char buf[16];
    std::snprintf(buf, sizeof buf, "arcus %02d", client_.address());
    return buf;
}

}  // namespace motorbus::arcus
