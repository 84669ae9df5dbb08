#include "motorbus/poll/stats.hpp"

#include <algorithm>
#include <cmath>

namespace motorbus::poll {

void Histogram::add(Nanos value) {
    value = std::max<Nanos>(value, 0);
    const auto bin = std::min<std::size_t>(static_cast<std::size_t>(value / kBin), kBins);
    ++bins_[bin];
    ++count_;
    max_ = std::max(max_, value);
}

Nanos Histogram::quantile(double q) const {
    if (count_ == 0) return 0;
    q = std::clamp(q, 0.0, 1.0);
    const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i <= kBins; ++i) {
        seen += bins_[i];
        if (seen >= rank) return std::min<Nanos>(static_cast<Nanos>(i + 1) * kBin, max_);
    }
    return max_;
}

}  // namespace motorbus::poll
