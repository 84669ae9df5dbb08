// Hardening (defect 3): a serial port is opened exclusively (TIOCEXCL + flock,
// as serial tools do).  A second opener -- in this process or another one --
// gets PortBusy (a LinkDown) naming the port and the holder's PID; the port is
// free again once the first holder closes it.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "motorbus/serial/line_server.hpp"
#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::serial;

namespace {

std::string busy_message(const std::string& path) {
    try {
        TtyPort second(path, 0);
    } catch (const PortBusy& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("wrong exception: ") + e.what();
    }
    return "opened";
}

// Runs this test binary again as a child process that opens `path` (see
// ChildOpener below); its exit code says what happened there.
int open_in_child(const std::string& path) {
    pid_t pid = ::fork();
    if (pid == 0) {
        ::setenv("MOTORBUS_TEST_OPEN_PATH", path.c_str(), 1);
        ::execl("/proc/self/exe", "test_serial", "--gtest_filter=PortExclusive.ChildOpener", nullptr);
        ::_exit(99);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 98;
}

}  // namespace

// Not a test of its own: the child side of open_in_child().  Exit 0 = refused
// with PortBusy naming the parent's PID, 1 = opened, 2 = another error.
TEST(PortExclusive, ChildOpener) {
    const char* path = std::getenv("MOTORBUS_TEST_OPEN_PATH");
    if (!path) GTEST_SKIP() << "runs only as the child of open_in_child()";
    const std::string m = busy_message(path);
    const std::string parent = "pid " + std::to_string(::getppid());
    std::_Exit(m == "opened" ? 1 : (m.find(parent) != std::string::npos && m.find(path) != std::string::npos) ? 0 : 2);
}

TEST(PortExclusive, SecondOpenInThisProcessRefusedNamingPortAndPid) {
    PtyPair pair;
    auto first = pair.open_slave();
    const std::string m = busy_message(pair.slave_path());
    EXPECT_NE(m.find(pair.slave_path()), std::string::npos) << m;
    EXPECT_NE(m.find("pid " + std::to_string(::getpid())), std::string::npos) << m;
    EXPECT_THROW(pair.open_slave(), LinkDown);  // PortBusy is a LinkDown (Python: motorbus.LinkDown)
    first->close();
    EXPECT_NO_THROW(pair.open_slave()->close());  // free again once closed
    EXPECT_NO_THROW(pair.open_slave());           // ... and again
}

TEST(PortExclusive, SecondOpenFromAnotherProcessRefused) {
    PtyPair pair;
    EXPECT_EQ(open_in_child(pair.slave_path()), 1);  // nobody holds it: the child opens it
    auto first = pair.open_slave();
    EXPECT_EQ(open_in_child(pair.slave_path()), 0);  // refused, naming our PID
    first.reset();
    EXPECT_EQ(open_in_child(pair.slave_path()), 1);
}

TEST(PortExclusive, PtyLineServerSlaveOpensOnceThenRefuses) {
    PtyLineServer server(std::vector<std::shared_ptr<LineDevice>>{});
    auto client = open_port(server.slave_path(), 115200);
    EXPECT_THROW(open_port(server.slave_path(), 115200), PortBusy);
    client->close();
    EXPECT_NO_THROW(open_port(server.slave_path(), 115200));
}
