// The typed errors every layer raises. Bindings map each one to a Python
// exception of the same name (see bindings/errors.cpp), so a caller can catch
// exactly what went wrong instead of parsing messages.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace motorbus {

// Base of everything motorbus throws on purpose.
struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A caller passed a value that can never be valid (bad frame id, DLC, option…).
// The message names the field and the allowed range.  Python: ValueError subclass.
struct InvalidArgument : Error {
    using Error::Error;
};

// A blocking call did not complete within its timeout.  Python: TimeoutError subclass.
struct TimeoutError : Error {
    using Error::Error;
};

// A peer sent bytes that do not follow the protocol.  Carries the offending bytes.
struct ProtocolError : Error {
    ProtocolError(const std::string& what, std::vector<std::uint8_t> offending = {})
        : Error(what), bytes(std::move(offending)) {}
    std::vector<std::uint8_t> bytes;
};

// The link to the peer is gone (EOF, EIO, TCP reset, bus closed under us).
// Python: ConnectionError subclass.
struct LinkDown : Error {
    using Error::Error;
};

// Operation on a bus/port that was closed by its owner.
struct ClosedError : Error {
    using Error::Error;
};

// The drive reported a fault, or rejected a command for a device-side reason.
struct DriveFault : Error {
    using Error::Error;
};

}  // namespace motorbus
