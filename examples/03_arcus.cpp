// 03: an Arcus DMX-CAN simulator on a pty (PtyLineServer, real time) and the
// C++ client talking to it over a LineLink.
#include <chrono>
#include <cstdio>
#include <memory>

#include "motorbus/drives/arcus/client.hpp"
#include "motorbus/drives/arcus/sim.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/serial/line_server.hpp"

using namespace motorbus;
using namespace std::chrono_literals;

int main() {
    arcus::SimOptions o;
    o.eo_boot = true;  // powered at boot (the factory EOBOOT=0 leaves the motor off)
    auto sim = std::make_shared<arcus::Sim>(std::make_shared<RealClock>(), o);
    serial::PtyLineServer server({sim});

    auto link = std::make_shared<serial::LineLink>(serial::open_port(server.slave_path(), 0),
                                                   arcus::Client::line_options(200ms));
    arcus::ClientOptions co;
    co.address = 1;
    arcus::Client c(link, co);
    c.set_high_speed(20000);  // encoder counts/s: StepNLoop is on
    c.set_acceleration(20);
    c.move(1250);
    c.wait_idle(5s);
    std::printf("EX=%lld PX=%lld SLS=%d\n", static_cast<long long>(c.encoder()),
                static_cast<long long>(c.position()), static_cast<int>(c.snl_status()));
    std::printf("SLR=%.3f ID=%s\n", c.snl_ratio(), c.id().c_str());
    server.close();
}
