// Poll sources for UNITEK drives (motorbus.Poller), on the drive's own Client:
//
// * PollSource asks: one `3D REGID 00` read per field each sample (the client
//   matches the reply; a commanding thread's reads of other REGIDs interleave);
// * CaptureSource captures: it subscribes the drive's cyclic transmission of
//   each register (`3D REGID t`, at most 8 cyclic registers per drive) and
//   each read() takes the latest value the bus receive thread put into the
//   register's stream ring — nothing is sent per sample.  Its row starts with
//   the arrival time (see poll/capture.hpp); a lost link throws LinkDown from
//   read(), as an asking source's request would.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motorbus/drives/unitek/client.hpp"
#include "motorbus/poll/capture.hpp"
#include "motorbus/poll/source.hpp"

namespace motorbus::unitek {

class PollSource final : public poll::Source {
public:
    // `client` must outlive the source (the bindings keep it alive).
    // UnknownRegister / InvalidArgument for a register the table lacks or cannot read.
    PollSource(Client& client, std::vector<std::uint8_t> regids);

    std::size_t columns() const override { return regids_.size(); }
    void read(double* out) override;
    std::string describe() const override;

private:
    Client& client_;
    std::vector<std::uint8_t> regids_;
};

class CaptureSource final : public poll::Source {
public:
    // Subscribes each register every `interval_ms` (1..254) unless it already
    // transmits cyclically (a user's Stream: then its interval is kept and the
    // stream is left running at close()).  Data older than max_age_ns (default:
    // 3 intervals + 2 ms) counts as stale.  CyclicLimit past 8 cyclic registers.
    CaptureSource(Client& client, can::Bus& bus, std::vector<std::uint8_t> regids, int interval_ms,
                  Nanos max_age_ns = 0);
    ~CaptureSource() override;

    std::size_t columns() const override { return regids_.size() + 1; }
    void read(double* out) override;
    std::string describe() const override;
    std::uint64_t stale() const override { return stale_.load(std::memory_order_relaxed); }

    // Stops the cyclic transmissions this source started (best effort: the link
    // may be gone).  Idempotent; read() keeps giving the last values.
    void close();
    int interval_ms() const { return interval_ms_; }
    Nanos max_age_ns() const { return max_age_; }

private:
    Client& client_;
    can::Bus& bus_;
    std::vector<std::uint8_t> regids_;
    std::vector<std::shared_ptr<Stream>> streams_;
    std::vector<std::uint8_t> owned_;  // subscribed by us: unsubscribed at close()
    int interval_ms_;
    Nanos max_age_;
    std::vector<Nanos> t_;
    std::vector<double> v_;
    std::atomic<std::uint64_t> stale_{0};
    std::atomic<bool> closed_{false};
};

}  // namespace motorbus::unitek
