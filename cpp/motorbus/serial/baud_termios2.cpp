// Arbitrary baud rates through the Linux termios2 interface (BOTHER).  Lives in
// its own translation unit because <asm/termbits.h> and glibc's <termios.h>
// define the same names differently and cannot be included together.
#include "baud_termios2.hpp"

#if defined(__linux__)
#include <asm/ioctls.h>
#include <asm/termbits.h>

extern "C" int ioctl(int fd, unsigned long request, ...);

namespace motorbus::serial::detail {

bool set_baud_termios2(int fd, unsigned baud) {
    struct termios2 tio {};
    if (ioctl(fd, TCGETS2, &tio) != 0) return false;
    tio.c_cflag &= ~static_cast<tcflag_t>(CBAUD);
    tio.c_cflag |= BOTHER;
    tio.c_ispeed = baud;
    tio.c_ospeed = baud;
    // Input speed follows the output speed field unless IBSHIFT says otherwise.
    tio.c_cflag &= ~static_cast<tcflag_t>(CBAUD << IBSHIFT);
    tio.c_cflag |= static_cast<tcflag_t>(BOTHER << IBSHIFT);
    if (ioctl(fd, TCSETS2, &tio) != 0) return false;
    struct termios2 check {};
    if (ioctl(fd, TCGETS2, &check) != 0) return false;
    return check.c_ospeed != 0;
}

unsigned get_baud_termios2(int fd) {
    struct termios2 tio {};
    if (ioctl(fd, TCGETS2, &tio) != 0) return 0;
    return tio.c_ospeed;
}

}  // namespace motorbus::serial::detail

#else

namespace motorbus::serial::detail {
bool set_baud_termios2(int, unsigned) { return false; }
unsigned get_baud_termios2(int) { return 0; }
}  // namespace motorbus::serial::detail

#endif
