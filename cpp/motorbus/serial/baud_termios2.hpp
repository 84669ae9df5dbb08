// Internal: non-standard baud rates (termios2/BOTHER) for TtyPort.
#pragma once

namespace motorbus::serial::detail {
// Sets both directions to `baud`; false if the driver or OS refuses.
bool set_baud_termios2(int fd, unsigned baud);
// The output speed the driver reports, 0 if unavailable.
unsigned get_baud_termios2(int fd);
}  // namespace motorbus::serial::detail
