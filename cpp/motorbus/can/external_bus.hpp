// A bus whose medium lives outside motorbus: the owner supplies the send
// function and feeds received frames in.  The python-can bridge is built on
// it (python/motorbus/bus.py): a reader thread pulls frames from the foreign
// bus and calls feed(); send() calls back into the foreign bus.
#pragma once
#include <functional>

#include "motorbus/can/bus.hpp"

namespace motorbus::can {

class ExternalBus final : public Bus {
public:
    // `send_fn` must put the frame on the foreign medium or throw
    // (TimeoutError when it stayed full until the deadline).
    using SendFn = std::function<void(const Frame&, Deadline)>;
    using CloseFn = std::function<void()>;
    ExternalBus(std::string channel, SendFn send_fn, CloseFn close_fn = {}, BusOptions opts = {});
    ~ExternalBus() override;

    // Delivers a frame received from the foreign medium (from the owner's
    // single reader thread).
    void feed(const Frame& f) {
        if (!closed()) dispatch(f);
    }
    void feed_parse_error() { count_parse_error(); }

protected:
    void do_send(const Frame& frame, Deadline deadline) override { send_fn_(frame, deadline); }
    void do_close() override {
        if (close_fn_) close_fn_();
    }

private:
    SendFn send_fn_;
    CloseFn close_fn_;
};

}  // namespace motorbus::can
