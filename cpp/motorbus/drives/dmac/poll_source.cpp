#include "motorbus/drives/dmac/poll_source.hpp"

#include "motorbus/errors.hpp"

namespace motorbus::dmac {

PollSource::PollSource(std::shared_ptr<serial::LineLink> link, ClientOptions options, std::vector<std::string> names)
    : client_(std::move(link), std::move(options)) {
    if (names.empty()) throw InvalidArgument("dmac poll source: at least one variable (POSITION, SPEED...)");
    for (const auto& n : names) {
        const auto v = find_variable(n);
        if (!v) throw InvalidArgument("dmac poll variable '" + n + "': not a DMAC variable");
        vars_.push_back(*v);
        radix_.push_back(*v == Var::Status || *v == Var::Error ? Radix::Hex : Radix::Dec);
    }
}

void PollSource::read(double* out) {
    for (std::size_t i = 0; i < vars_.size(); ++i) out[i] = client_.read(vars_[i], radix_[i]);
}

std::string PollSource::describe() const { return "dmac " + std::to_string(client_.address()); }

}  // namespace motorbus::dmac
