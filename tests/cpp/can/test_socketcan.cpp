// SocketCAN backend: what needs no kernel CAN support (struct conversions,
// filter translation, error-frame states) and a live vcan0 test that skips on
// kernels without CONFIG_CAN.
#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <cstring>
#include <vector>

#include "motorbus/can/socketcan_bus.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;

TEST(SocketCan, ClassicFrameToKernelStruct) {
    std::vector<std::uint8_t> d{0xDE, 0xAD, 0xBE};
    auto k = socketcan::to_can_frame(Frame::make(0x123, d));
    EXPECT_EQ(k.can_id, 0x123u);
    EXPECT_EQ(k.len, 3);
    EXPECT_EQ(k.data[0], 0xDE);
    EXPECT_EQ(k.data[2], 0xBE);
    EXPECT_EQ(k.data[3], 0);  // the rest is zeroed, no stale bytes on the wire
    auto x = socketcan::to_can_frame(Frame::make(0x1ABCDEF0, {}, true));
    EXPECT_EQ(x.can_id, 0x1ABCDEF0u | CAN_EFF_FLAG);
    auto r = socketcan::to_can_frame(Frame::make(0x7FF, {}, false, true, 5));
    EXPECT_EQ(r.can_id, 0x7FFu | CAN_RTR_FLAG);
    EXPECT_EQ(r.len, 5);
}

TEST(SocketCan, RefusesFramesTheKernelCannotTake) {
    Frame fd;
    fd.id = 0x10;
    fd.flags = kFlagFd;
    fd.len = 12;
    EXPECT_THROW(socketcan::to_can_frame(fd), InvalidArgument);
    auto kfd = socketcan::to_canfd_frame(fd);
    EXPECT_EQ(kfd.len, 12);
    EXPECT_TRUE(kfd.flags & CANFD_FDF);
    Frame err;
    err.flags = kFlagError;
    EXPECT_THROW(socketcan::to_can_frame(err), InvalidArgument);
    Frame bad;
    bad.id = 0x800;  // standard id out of range
    EXPECT_THROW(socketcan::to_can_frame(bad), InvalidArgument);
}

TEST(SocketCan, KernelStructToFrame) {
    struct can_frame k;
    std::memset(&k, 0, sizeof k);
    k.can_id = 0x1FFFFFFF | CAN_EFF_FLAG;
    k.len = 8;
    for (int i = 0; i < 8; ++i) k.data[i] = static_cast<std::uint8_t>(i + 1);
    auto f = socketcan::from_kernel(&k, CAN_MTU, 1234);
    ASSERT_TRUE(f.has_value());
    EXPECT_TRUE(f->extended);
    EXPECT_EQ(f->id, 0x1FFFFFFFu);
    EXPECT_EQ(f->len, 8);
    EXPECT_EQ(f->data[7], 8);
    EXPECT_EQ(f->timestamp_ns, 1234);

    k.can_id = 0x123 | CAN_RTR_FLAG;
    k.len = 2;
    auto r = socketcan::from_kernel(&k, CAN_MTU, 0);
    ASSERT_TRUE(r.has_value());
    EXPECT_TRUE(r->rtr);
    EXPECT_FALSE(r->extended);
    EXPECT_EQ(r->len, 2);
    EXPECT_EQ(r->payload().size(), 0u);

    k.len = 9;  // a length the kernel never produces for classic CAN
    EXPECT_FALSE(socketcan::from_kernel(&k, CAN_MTU, 0).has_value());
    EXPECT_FALSE(socketcan::from_kernel(&k, 7, 0).has_value());  // short read

    struct canfd_frame kf;
    std::memset(&kf, 0, sizeof kf);
    kf.can_id = 0x55;
    kf.len = 64;
    kf.flags = CANFD_BRS;
    kf.data[63] = 0xAA;
    auto g = socketcan::from_kernel(&kf, CANFD_MTU, 0);
    ASSERT_TRUE(g.has_value());
    EXPECT_TRUE(g->is_fd());
    EXPECT_TRUE(g->flags & kFlagBrs);
    EXPECT_EQ(g->data[63], 0xAA);
    kf.len = 13;  // not a CAN FD length
    EXPECT_FALSE(socketcan::from_kernel(&kf, CANFD_MTU, 0).has_value());
}

TEST(SocketCan, RoundTripEveryIdWidthAndDlc) {
    static constexpr std::uint8_t b[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    for (bool ext : {false, true})
        for (std::uint32_t id : {0u, 0x7FFu, 0x1FFFFFFFu}) {
            if (!ext && id > 0x7FF) continue;
            for (std::size_t len = 0; len <= 8; ++len) {
                Frame f = Frame::make(id, std::span(b, len), ext);
                auto k = socketcan::to_can_frame(f);
                auto back = socketcan::from_kernel(&k, CAN_MTU, 0);
                ASSERT_TRUE(back.has_value());
                EXPECT_TRUE(back->same_content(f)) << f.to_string();
            }
        }
}

TEST(SocketCan, ErrorFramesBecomeFlaggedFramesAndStates) {
    struct can_frame k;
    std::memset(&k, 0, sizeof k);
    k.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
    k.len = CAN_ERR_DLC;
    k.data[1] = CAN_ERR_CRTL_TX_PASSIVE;
    auto e = socketcan::from_kernel(&k, CAN_MTU, 0);
    ASSERT_TRUE(e.has_value());
    EXPECT_TRUE(e->flags & kFlagError);
    EXPECT_EQ(e->id, static_cast<std::uint32_t>(CAN_ERR_CRTL));
    EXPECT_EQ(socketcan::state_after_error(*e, BusState::Active), BusState::ErrorPassive);
    e->data[1] = CAN_ERR_CRTL_RX_WARNING;
    EXPECT_EQ(socketcan::state_after_error(*e, BusState::Active), BusState::ErrorWarning);
    e->data[1] = CAN_ERR_CRTL_ACTIVE;
    EXPECT_EQ(socketcan::state_after_error(*e, BusState::ErrorPassive), BusState::Active);
    Frame off = *e;
    off.id = CAN_ERR_BUSOFF;
    EXPECT_EQ(socketcan::state_after_error(off, BusState::ErrorPassive), BusState::BusOff);
    Frame restarted = *e;
    restarted.id = CAN_ERR_RESTARTED;
    EXPECT_EQ(socketcan::state_after_error(restarted, BusState::BusOff), BusState::Active);
    EXPECT_EQ(socketcan::state_after_error(Frame::make(1, {}), BusState::ErrorWarning),
              BusState::ErrorWarning);  // a data frame changes nothing
}

TEST(SocketCan, FiltersTranslateToTheKernelsMatchingRule) {
    // The kernel's rule: (received_can_id & can_mask) == (can_id & can_mask).
    auto kernel_accepts = [](const struct can_filter& k, const Frame& f) {
        canid_t id = f.extended ? (f.id | CAN_EFF_FLAG) : f.id;
        return (id & k.can_mask) == (k.can_id & k.can_mask);
    };
    std::vector<Filter> ours = {
        Filter{0x123, 0x7FF, false, true},         // exactly standard 0x123
        Filter{0x18FF0000, 0x1FFF0000, true, true},  // extended, a PGN range
        Filter{0x100, 0x700, false, false},        // any width, ids 0x1xx
        Filter{},                                   // accept all
    };
    auto k = socketcan::to_kernel_filters(ours);
    ASSERT_EQ(k.size(), 4u);
    EXPECT_EQ(k[0].can_id, 0x123u);
    EXPECT_EQ(k[0].can_mask, 0x7FFu | CAN_EFF_FLAG);
    EXPECT_EQ(k[1].can_id, 0x18FF0000u | CAN_EFF_FLAG);
    EXPECT_EQ(k[2].can_mask, 0x700u);
    EXPECT_EQ(k[3].can_mask, 0u);
    std::vector<Frame> probes = {
        Frame::make(0x123, {}),        Frame::make(0x123, {}, true), Frame::make(0x124, {}),
        Frame::make(0x18FF1234, {}, true), Frame::make(0x18FE1234, {}, true),
        Frame::make(0x1F0, {}),        Frame::make(0x1F0, {}, true), Frame::make(0x7F0, {}),
    };
    for (std::size_t i = 0; i < ours.size(); ++i)
        for (const Frame& f : probes)
            EXPECT_EQ(kernel_accepts(k[i], f), ours[i].matches(f))
                << "filter " << i << " frame " << f.to_string() << (f.extended ? " ext" : "");
}

TEST(SocketCan, LiveVcan0OrSkipWhenTheKernelHasNoCan) {
    if (auto why = socketcan::unavailable_reason()) {
        // This is the expected path on kernels built without CONFIG_CAN.
        EXPECT_NE(why->find("EAFNOSUPPORT"), std::string::npos) << *why;
        try {
            open_socketcan("vcan0");
            ADD_FAILURE() << "opened a CAN socket on a kernel that has none";
        } catch (const LinkDown& e) {
            EXPECT_EQ(std::string(e.what()), *why);
        }
        GTEST_SKIP() << *why;
    }
    std::shared_ptr<SocketCanBus> a, b;
    try {
        a = open_socketcan("vcan0");
        b = open_socketcan("vcan0");
    } catch (const LinkDown& e) {
        GTEST_SKIP() << "CAN works but no vcan0: " << e.what();
    }
    std::vector<std::uint8_t> d{1, 2, 3};
    a->send(Frame::make(0x321, d));
    auto got = b->recv(std::chrono::seconds(2));
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(got->id, 0x321u);
    EXPECT_GT(got->timestamp_ns, 0);
}
