// A poll source: what one PollGroup thread asks (or captures) from one drive
// each period.  The generic poller knows nothing of protocols; each transport
// or vendor supplies sources built on its own native client (an SDO object
// source beside the CANopen code, an ASCII query source in a vendor folder...).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace motorbus::poll {

class Source {
public:
    virtual ~Source() = default;
    // How many values read() writes (one per field: position, velocity, ...).
    virtual std::size_t columns() const = 0;
    // Reads one sample's values into out[0 .. columns()), in native units as
    // numbers.  Called only from the poll thread, without the GIL.  A transport
    // failure throws (LinkDown, TimeoutError...): it ends the poll group.
    virtual void read(double* out) = 0;
    // "SDO node 5": names the source in errors and stats.
    virtual std::string describe() const = 0;
    // Capture sources (the drive pushes, read() takes the latest pushed values):
    // how many read() calls found data older than the push period allows (or
    // none yet).  A push that stopped shows here, never as silent repetition.
    // Sources that ask return 0.  Read from any thread.
    virtual std::uint64_t stale() const { return 0; }
};

}  // namespace motorbus::poll
