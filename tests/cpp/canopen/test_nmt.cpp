#include <gtest/gtest.h>

#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/errors.hpp"
#include "test_nmt_support.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using svc_test::bytes;
using svc_test::frame;

TEST(NmtCodec, EncodesEveryCommand) {
    EXPECT_EQ(bytes(encode_nmt(NmtCommand::Start, 5)), (std::vector<std::uint8_t>{0x01, 0x05}));
    EXPECT_EQ(bytes(encode_nmt(NmtCommand::Stop, 5)), (std::vector<std::uint8_t>{0x02, 0x05}));
    EXPECT_EQ(bytes(encode_nmt(NmtCommand::EnterPreOperational, 0)), (std::vector<std::uint8_t>{0x80, 0x00}));
    EXPECT_EQ(bytes(encode_nmt(NmtCommand::ResetNode, 127)), (std::vector<std::uint8_t>{0x81, 0x7F}));
    EXPECT_EQ(bytes(encode_nmt(NmtCommand::ResetCommunication, 1)), (std::vector<std::uint8_t>{0x82, 0x01}));
    EXPECT_EQ(encode_nmt(NmtCommand::Start, 5).id, 0x000u);
    EXPECT_THROW(encode_nmt(NmtCommand::Start, 128), InvalidArgument);
}

TEST(NmtCodec, N1_DlcNotTwoIgnored) {
    EXPECT_FALSE(decode_nmt(frame(0, {0x01})));
    EXPECT_FALSE(decode_nmt(frame(0, {0x01, 0x05, 0x00})));
    EXPECT_FALSE(decode_nmt(frame(0, {})));
    EXPECT_TRUE(decode_nmt(frame(0, {0x01, 0x05})));
}

TEST(NmtSlave, N1_N2_N3_N4_IgnoreMalformedApplyBroadcast) {
    NmtSlave s(5);
    s.boot();
    EXPECT_EQ(s.state(), NodeState::PreOperational);
    EXPECT_FALSE(s.on_frame(frame(0, {0x01})));             // N1: DLC 1
    EXPECT_FALSE(s.on_frame(frame(0, {0x01, 0x05, 0})));    // N1: DLC 3
    EXPECT_FALSE(s.on_frame(frame(0, {0x01, 0x85})));       // N2: node 133
    EXPECT_FALSE(s.on_frame(frame(0, {0x01, 0xFF})));       // N2: node 255
    EXPECT_FALSE(s.on_frame(frame(0, {0x03, 0x05})));       // N4: unknown CS
    EXPECT_FALSE(s.on_frame(frame(0, {0xFF, 0x00})));       // N4
    EXPECT_FALSE(s.on_frame(frame(0, {0x01, 0x06})));       // another node
    EXPECT_EQ(s.state(), NodeState::PreOperational);
    EXPECT_EQ(s.ignored(), 7u);
    // N3: node 0 applies to us.
    EXPECT_EQ(s.on_frame(frame(0, {0x01, 0x00})), NmtCommand::Start);
    EXPECT_EQ(s.state(), NodeState::Operational);
    // Next valid input still works.
    EXPECT_EQ(s.on_frame(frame(0, {0x02, 0x05})), NmtCommand::Stop);
    EXPECT_EQ(s.state(), NodeState::Stopped);
    int resets = 0;
    s.on_reset = [&](NmtCommand c) { resets += c == NmtCommand::ResetCommunication; };
    s.on_frame(frame(0, {0x82, 0x05}));
    EXPECT_EQ(resets, 1);
    EXPECT_EQ(s.state(), NodeState::Initialising);
}

TEST(NmtSlave, N14_RefusesNodeIdZeroOrAbove127) {
    EXPECT_THROW(NmtSlave(0), InvalidArgument);
    EXPECT_THROW(NmtSlave(128), InvalidArgument);
    EXPECT_THROW(NmtSlave(255), InvalidArgument);
    EXPECT_NO_THROW(NmtSlave(127));
}

TEST(NmtMaster, SendsCommandsAndTracksStates) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto dev = hub.open("dev");
    NmtMaster m(*host);
    m.start(5);
    m.reset_node(0);
    m.enter_pre_operational(3);
    ASSERT_EQ(hub.log.size(), 3u);
    EXPECT_EQ(bytes(hub.log[0]), (std::vector<std::uint8_t>{0x01, 0x05}));
    EXPECT_EQ(bytes(hub.log[1]), (std::vector<std::uint8_t>{0x81, 0x00}));
    EXPECT_EQ(bytes(hub.log[2]), (std::vector<std::uint8_t>{0x80, 0x03}));

    std::vector<std::tuple<int, NodeState, NodeState>> changes;
    m.on_state_change = [&](std::uint8_t n, NodeState a, NodeState b) { changes.emplace_back(n, a, b); };
    EXPECT_EQ(m.state(5), NodeState::Unknown);
    dev->send(encode_heartbeat(5, NodeState::Initialising));  // boot-up
    EXPECT_EQ(m.state(5), NodeState::Initialising);
    dev->send(encode_heartbeat(5, NodeState::PreOperational));
    dev->send(encode_heartbeat(5, NodeState::PreOperational));  // no change, no callback
    dev->send(encode_heartbeat(5, NodeState::Operational));
    EXPECT_EQ(m.state(5), NodeState::Operational);
    ASSERT_EQ(changes.size(), 3u);
    EXPECT_EQ(changes[2], std::make_tuple(5, NodeState::PreOperational, NodeState::Operational));
    EXPECT_TRUE(m.wait_for_state(5, NodeState::Operational, std::chrono::milliseconds(1)));
    EXPECT_FALSE(m.wait_for_state(5, NodeState::Stopped, std::chrono::milliseconds(1)));
    // N7 on the master: an odd state byte is UNKNOWN, never operational.
    dev->send(frame(0x705, {0x42}));
    EXPECT_EQ(m.state(5), NodeState::Unknown);
    EXPECT_EQ(m.raw_state(5), 0x42);
}

TEST(NmtMaster, N5_CommandsAimedAtTheMasterAreIgnored) {
    svc_test::Hub hub;
    auto host = hub.open("host");
    auto rogue = hub.open("rogue");
    NmtMaster m(*host, std::uint8_t{1});
    rogue->send(frame(0, {0x81, 0x01}));
    rogue->send(frame(0, {0x81, 0x00}));
    rogue->send(frame(0, {0x81, 0x02}));  // not for the master
    EXPECT_EQ(m.foreign_commands_ignored(), 2u);
    // The master keeps working.
    m.start(2);
    EXPECT_EQ(bytes(hub.log.back()), (std::vector<std::uint8_t>{0x01, 0x02}));
}
