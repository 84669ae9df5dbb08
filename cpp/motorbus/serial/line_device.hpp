// What a simulated serial device implements: it is handed each complete
// request line and answers with the exact bytes the real device would send.
// CONTRACT shared by the serial line server (serial/) and the drive
// simulators (drives/*/sim.*).
#pragma once
#include <string>
#include <string_view>

namespace motorbus::serial {

class LineDevice {
public:
    virtual ~LineDevice() = default;
    // `line` is one request without its terminator.  Returns the reply bytes,
    // terminator included ("" = stay silent, e.g. not addressed / broadcast).
    // Must never throw on any input: hostile bytes get the device's error reply.
    virtual std::string on_line(std::string_view line) = 0;
    // The line's last byte reaches every device on the wire at one instant, but the
    // line server hands the line to them one after the other.  It calls this on every
    // device first, so a device whose command acts at an instant (a broadcast start
    // trigger) can take that instant here rather than when its own turn comes.
    virtual void line_ends() {}
    // The request terminator this device expects (e.g. "\r").
    virtual std::string request_terminator() const { return "\r"; }
    // Longest request line the device buffers; longer input is discarded up to
    // the next terminator and answered like the real device would (or not at all).
    virtual std::size_t max_request() const { return 256; }
    // Reply for an over-long request line ("" = silent).
    virtual std::string on_overlong() { return ""; }
};

}  // namespace motorbus::serial
