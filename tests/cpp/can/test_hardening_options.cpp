// Hardening (defects 1 and 11): every size/count option and fault probability
// is validated where it enters the C++ core, so a bad value is an
// InvalidArgument naming the option and its range, never a hang or a corrupt heap.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "../invalid_message.hpp"
#include "motorbus/can/external_bus.hpp"
#include "motorbus/can/slcan_bus.hpp"
#include "motorbus/can/slcan_server.hpp"
#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_server.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;

using motorbus::test::invalid_message;

TEST(HardeningOptions, RxQueueSizeZeroRefusedOnEveryBus) {
    VirtualOptions v;
    v.rx_queue_size = 0;
    auto m = invalid_message([&] { open_virtual("hardening-rxq", v); });
    EXPECT_NE(m.find("rx_queue_size"), std::string::npos) << m;
    EXPECT_NE(m.find(">= 1"), std::string::npos) << m;
    BusOptions b;
    b.rx_queue_size = 0;
    m = invalid_message([&] { ExternalBus("ext", [](const Frame&, Deadline) {}, {}, b); });
    EXPECT_NE(m.find("rx_queue_size"), std::string::npos) << m;
}

TEST(HardeningOptions, RxQueueSizeOneKeepsTheNewestFrame) {
    VirtualOptions v;
    v.rx_queue_size = 1;
    auto a = open_virtual("hardening-rxq1", v);
    auto b = open_virtual("hardening-rxq1", v);
    for (std::uint32_t id = 1; id <= 3; ++id) a->send(Frame::make(id, {}));
    auto f = b->recv(std::chrono::seconds(1));
    ASSERT_TRUE(f);
    EXPECT_EQ(f->id, 3u);
    EXPECT_EQ(b->counters().rx_dropped, 2u);
}

TEST(HardeningOptions, VirtualTxQueueZeroRefused) {
    VirtualOptions v;
    v.bitrate = 500'000;
    v.tx_queue = 0;
    auto m = invalid_message([&] { open_virtual("hardening-txq", v); });
    EXPECT_NE(m.find("tx_queue"), std::string::npos) << m;
}

TEST(HardeningOptions, FaultProbabilitiesOutsideZeroOneRefused) {
    auto bus = open_virtual("hardening-faults");
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (double p : {-0.1, 1.5, nan}) {
        FaultOptions f;
        f.drop_probability = p;
        auto m = invalid_message([&] { bus->set_faults(f); });
        EXPECT_NE(m.find("drop_probability"), std::string::npos) << p << ": " << m;
        EXPECT_NE(m.find("[0, 1]"), std::string::npos) << m;
        FaultOptions c;
        c.corrupt_probability = p;
        m = invalid_message([&] { bus->set_faults(c); });
        EXPECT_NE(m.find("corrupt_probability"), std::string::npos) << p << ": " << m;
    }
    FaultOptions d;
    d.delay_ns = -1;
    EXPECT_NE(invalid_message([&] { bus->set_faults(d); }).find("delay"), std::string::npos);
    VirtualOptions v;
    v.faults.drop_probability = 2.0;
    EXPECT_NE(invalid_message([&] { open_virtual("hardening-faults2", v); }).find("drop_probability"),
              std::string::npos);
    FaultOptions ok;
    ok.drop_probability = 1.0;
    ok.corrupt_probability = 0.0;
    EXPECT_NO_THROW(bus->set_faults(ok));
}

// C3-C7 of docs/reliability.md: options that were accepted and left an object
// that could never work.  check_options() is what every constructor calls.
TEST(HardeningOptions, SocketcandClientOptionsRefusedByName) {
    SocketcandOptions o;
    o.tx_buffer_bytes = 0;  // C3: send() would wait for room forever
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("tx_buffer_bytes"), std::string::npos);
    o = {};
    o.max_element = 10;  // no frame element fits
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("max_element"), std::string::npos);
    o = {};
    o.keepalive_period = -std::chrono::seconds(1);
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("keepalive_period"), std::string::npos);
    o = {};
    o.rx_queue_size = 0;
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("rx_queue_size"), std::string::npos);
    EXPECT_NO_THROW(check_options(SocketcandOptions{}));
}

TEST(HardeningOptions, SocketcandServerOptionsRefusedByName) {
    SocketcandServerOptions o;
    o.max_clients = 0;  // C5
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("max_clients"), std::string::npos);
    for (const char* bad : {"a b", "a<b", "tab\there", "seventeen-chars-x"}) {  // C6
        o = {};
        o.channel = bad;
        EXPECT_NE(invalid_message([&] { check_options(o); }).find("channel"), std::string::npos) << bad;
    }
    o = {};
    o.channel = "";  // = accept any name
    EXPECT_NO_THROW(check_options(o));
    o.channel = "can0";
    EXPECT_NO_THROW(check_options(o));
}

TEST(HardeningOptions, SlcanServerIdentityMustFitTheReplies) {
    SlcanServerOptions o;
    EXPECT_NO_THROW(check_options(o));  // V1013 / NMB01
    for (const char* bad : {"toolong-version", "V12", "X1013", "V10\r3", ""}) {  // C7
        o = {};
        o.identity.version = bad;
        EXPECT_NE(invalid_message([&] { check_options(o); }).find("version"), std::string::npos) << bad;
    }
    o = {};
    o.identity.serial = "toolong-serial";
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("serial_number"), std::string::npos);
}

TEST(HardeningOptions, SlcanClientOptionsRefusedByName) {
    SlcanOptions o;
    o.bitrate = 0;  // documented: keep the adapter's rate
    EXPECT_NO_THROW(check_options(o));
    o.bitrate = 83333;
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("bitrate"), std::string::npos);
    o = {};
    o.reconnect_min = std::chrono::seconds(10);
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("reconnect_min"), std::string::npos);
    o = {};
    o.ack_timeout = -std::chrono::milliseconds(1);
    EXPECT_NE(invalid_message([&] { check_options(o); }).find("ack_timeout"), std::string::npos);
}
