// The PMC007 simulator against the manual (003) and the spec's §1 rows, over
// an in-process CAN bus with the generic SdoClient as the host.  Motion time is
// a SimClock advanced by the test.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/eds.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/drives/pmc007/od_table.hpp"
#include "motorbus/drives/pmc007/program.hpp"
#include "motorbus/drives/pmc007/sim.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::pmc007;
using namespace std::chrono_literals;

namespace {

std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

std::uint32_t abort_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const canopen::SdoAbortError& e) {
        return e.code;
    }
    return 0;
}

struct SimFixture : ::testing::Test {
    SimClock clock{1'000'000'000};
    std::string hub = "pmc007-" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
    std::shared_ptr<can::VirtualBus> dev = can::open_virtual(hub);
    std::shared_ptr<can::VirtualBus> host = can::open_virtual(hub);
    std::unique_ptr<Sim> sim;
    std::unique_ptr<canopen::SdoClient> sdo;

    void SetUp() override {
        sim = std::make_unique<Sim>(5, clock);
        sim->attach(dev);
        sdo = std::make_unique<canopen::SdoClient>(*host, 5);
    }
    void TearDown() override {
        sdo.reset();
        sim.reset();
    }
    void advance(double s) {
        clock.advance(Nanos(s * 1e9));
        sim->poll();
    }
};

}  // namespace

// ---- the one table, the EDS ----------------------------------------------------------

TEST(Pmc007Table, CountsOfTheSpec) {
    std::set<std::uint16_t> indices;
    for (const auto& r : od_rows()) indices.insert(r.index);
    EXPECT_EQ(indices.size(), 73u);
    EXPECT_EQ(od_rows().size(), 210u);
    // B-P31: mappable exactly 1001h, 1002h, 1003h:01-07, 1007h, 6000h, 6001h, 600Ch, 6012h.
    std::set<std::pair<int, int>> mappable;
    for (const auto& r : od_rows())
        if (r.pdo) mappable.insert({r.index, r.sub});
    EXPECT_EQ(mappable.size(), 14u);
    EXPECT_TRUE(mappable.count({0x6012, 0}));
    EXPECT_FALSE(mappable.count({0x6004, 0}));
}

// The shipped EDS is the generated one.  MOTORBUS_WRITE_EDS=1 regenerates it.
TEST(Pmc007Table, ShippedEdsIsGenerated) {
    const std::string path = std::string(MOTORBUS_TEST_DATA) + "/../cpp/motorbus/drives/pmc007/pmc007.eds";
    const std::string text = eds();
    if (const char* w = std::getenv("MOTORBUS_WRITE_EDS"); w && std::string(w) == "1") {
        std::ofstream(path, std::ios::binary) << text;
    }
    const std::string shipped = read_file(path);
    if (shipped != text) {
        std::size_t i = 0;
        while (i < shipped.size() && i < text.size() && shipped[i] == text[i]) ++i;
        ADD_FAILURE() << path << " differs from the generated EDS at byte " << i
                      << "; run MOTORBUS_WRITE_EDS=1 build/dev/test_pmc007 to regenerate";
    }
    auto od = canopen::parse_eds(text, {.node_id = 5});
    EXPECT_EQ(od->indices().size(), 73u);
    EXPECT_EQ(od->at(0x1800, 1)->get_u64(), 0x185u);
    EXPECT_EQ(od->at(0x2003, 0)->get_u64(), 4u);  // [D] index 4 = 125 kbit/s
}

// ---- offline program codec -------------------------------------------------------------

TEST(Pmc007Program, EveryInstructionRoundTrips) {
    const char* text =
        "ROT 0,3200\nMIC 0,16\nDIR 0,1\nEXTEN 0,1\nFREE 0,0\nCLR2 0,0\nCLR1 0,0\nVSET 0,6000\nACC 0,3\n"
        "TRIG 0,3\nCNTI 0,0\nCNTC 0,0\nJMP 0,0\nJNE 0,5\nJEQ 0,99\nWAIT 1,0\nOUT 5,1\nCMP 1,65536\n"
        "RESET_EN 1,10\nPAUSE_EN 1,0\n";
    auto words = assemble(text);
    ASSERT_EQ(words.size(), 20u);
    EXPECT_EQ(words[0], 0x01000C80u);  // opcode 1, option 0, data 3200
    EXPECT_EQ(words[15], 0x10100000u);  // WAIT 1,0
    EXPECT_EQ(disassemble(words), text);
    for (std::uint32_t i = 0; i < 20; ++i) EXPECT_EQ(decode(words[i])->op, static_cast<Opcode>(i + 1));
}

TEST(Pmc007Program, BadTextNamesTheLine) {
    try {
        assemble("ROT 0,10\nFLY 0,1\n");
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos);
    }
    EXPECT_THROW(assemble("ROT 0,0"), InvalidArgument);     // 1..65536
    EXPECT_THROW(assemble("MIC 0,3"), InvalidArgument);
    EXPECT_THROW(assemble("WAIT 0,0"), InvalidArgument);    // option 1..9
    EXPECT_THROW(assemble("JMP 0,100"), InvalidArgument);   // C-P11: 0..99
    EXPECT_EQ(disassemble_word(0xFF000001u), "RAW 0xFF000001");
    EXPECT_EQ(assemble("RAW 0xFF000001")[0], 0xFF000001u);  // raw words survive
}

// ---- SDO, worked examples ------------------------------------------------------------------

TEST_F(SimFixture, WorkedExamplesOfAppendix2) {
    // E-P04: 2003h := 7 answered 60; reads back 7 (RAM copy), the active baud stays 4 (B-P36).
    sdo->write_u8(0x2003, 0, 7);
    EXPECT_EQ(sdo->read_u8(0x2003, 0), 7);
    EXPECT_EQ(sim->active_baud_index(), 4);
    // E-P02: 6001h = 0x08 while a step command runs.
    sdo->write_i32(0x6003, 0, 1000);
    sdo->write_u32(0x6004, 0, 3200);
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 0x08);
    // E-P05: step refused with 08000022 while an error is latched.
    advance(10);
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 0x00);
    sim->inject_error(err::kUvlo);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x6004, 0, 3200); }), 0x08000022u);
    sdo->write_u8(0x6000, 0, err::kUvlo);  // write 1 to clear
    EXPECT_EQ(sdo->read_u8(0x6000, 0), 0);
    sdo->write_u32(0x6004, 0, 3200);
    EXPECT_TRUE(sim->busy());
}

TEST_F(SimFixture, AbortSelection) {
    EXPECT_EQ(abort_of([&] { sdo->read_u8(0x6030, 0); }), 0x06020000u);
    EXPECT_EQ(abort_of([&] { sdo->read_u8(0x600F, 3); }), 0x06090011u);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x1000, 0, 1); }), 0x06010002u);
    EXPECT_EQ(abort_of([&] { sdo->write_u16(0x600A, 0, 3); }), 0x06090030u);
    EXPECT_EQ(abort_of([&] { sdo->write_u16(0x6017, 0, 0x64E7); }), 0x06090030u);
    EXPECT_EQ(abort_of([&] { sdo->write_u8(0x2007, 0, 4); }), 0x06090030u);
    EXPECT_EQ(sdo->read_u8(0x2007, 0), 0);
    EXPECT_EQ(sdo->read_string(0x1008, 0), "PMC007 (motorbus sim)");  // segmented upload
    // Issue 23 #12: value sets answer 06090030, a mapping count above 8 06040042.
    EXPECT_EQ(abort_of([&] { sdo->write_u8(0x1003, 0, 8); }), 0x06090030u);
    EXPECT_EQ(abort_of([&] { sdo->write_u16(0x600A, 0, 512); }), 0x06090030u);
    EXPECT_EQ(abort_of([&] { sdo->write_u8(0x6020, 0, 1); }), 0x06090030u);
    EXPECT_EQ(abort_of([&] { sdo->write_u8(0x1A00, 0, 9); }), 0x06040042u);
    EXPECT_EQ(abort_of([&] { sdo->write_u16(0x6021, 0, 700); }), 0x06090030u);
    sdo->write_u8(0x6019, 1, 100);  // #13: the pointer reaches 100
    EXPECT_EQ(sdo->read_u8(0x6019, 1), 100);
}

// Issue 23 #6, #10, #12: no RTR answer, any COB-ID, SYNC on the 1005h COB-ID.
TEST_F(SimFixture, PdoRtrNeverSyncOnItsCobIdAnyCobId) {
    sdo->write_u32(0x1800, 1, 0x120);  // CiA 301 restricted range: accepted
    sdo->write_u8(0x1800, 2, 1);       // every SYNC
    sdo->write_u8(0x1A00, 0, 1);
    sdo->write_u32(0x1A00, 1, 0x60010008);
    std::atomic<int> tpdos{0};
    auto sub = host->subscribe(can::Filter{0x120, 0x7FF}, [&](const can::Frame& f) {
        if (!f.rtr) ++tpdos;
    });
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x01, 5}));
    std::this_thread::sleep_for(50ms);
    can::Frame rtr;
    rtr.id = 0x120;
    rtr.rtr = true;
    rtr.len = 1;
    host->send(rtr);
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(tpdos.load(), 0);
    sdo->write_u32(0x1005, 0, 0x81);
    host->send(can::Frame::make(0x080, std::span<const std::uint8_t>{}));
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(tpdos.load(), 0);
    host->send(can::Frame::make(0x081, std::span<const std::uint8_t>{}));
    for (int i = 0; i < 100 && tpdos.load() == 0; ++i) std::this_thread::sleep_for(5ms);
    EXPECT_EQ(tpdos.load(), 1);
    host->unsubscribe(sub);
}

// ---- motion --------------------------------------------------------------------------------

TEST_F(SimFixture, StepCommandBusyIgnoreAndDirection) {
    sdo->write_i32(0x6003, 0, 1000);  // B-P10: positive -> 6002h = 1
    EXPECT_EQ(sdo->read_u8(0x6002, 0), 1);
    sdo->write_u32(0x6004, 0, 2000);  // 2 s at 1000 pps (no ramps: gear 0)
    advance(0.5);
    sdo->write_u32(0x6004, 0, 50000);  // B-P07: ignored while busy, still acknowledged
    EXPECT_EQ(sdo->read_u32(0x6004, 0), 2000u);
    advance(2);
    EXPECT_EQ(sdo->read_i32(0x600C, 0), 2000);
    sdo->write_i32(0x6003, 0, -500);  // negative -> 6002h = 0, counts down
    EXPECT_EQ(sdo->read_u8(0x6002, 0), 0);
    sdo->write_u32(0x6004, 0, 500);
    advance(1.5);
    EXPECT_EQ(sdo->read_i32(0x600C, 0), 1500);
    sdo->write_i32(0x601C, 0, -100);  // absolute
    advance(5);
    EXPECT_EQ(sdo->read_i32(0x600C, 0), -100);
}

TEST_F(SimFixture, SpeedModeStopAndRelease) {
    sdo->write_u8(0x6005, 0, 1);
    sdo->write_i32(0x6003, 0, 800);
    advance(1);
    EXPECT_NEAR(sim->velocity(), 800, 1e-6);
    sdo->write_u8(0x6020, 0, 0);  // B-P14
    EXPECT_FALSE(sim->busy());
    sdo->write_i32(0x6003, 0, 800);
    EXPECT_TRUE(sim->busy());
    sdo->write_u32(0x6020, 0, 0);  // [D] the U32 form of 6020h (§4.5.7) is accepted too
    EXPECT_FALSE(sim->busy());
    EXPECT_EQ(sdo->upload(0x6020, 0).size(), 1u);  // read back as 1 byte
    sdo->write_i32(0x6003, 0, -800);
    advance(1);
    EXPECT_TRUE(sim->busy());
    sdo->write_u8(0x600E, 0, 0);  // B-P20: released, then refused
    EXPECT_FALSE(sim->busy());
    sdo->write_u8(0x6005, 0, 0);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x6004, 0, 10); }), 0x08000022u);
    sdo->write_u8(0x600E, 0, 1);
    sdo->write_u32(0x6004, 0, 10);
}

TEST_F(SimFixture, StallJamLatchesAndStops) {
    sdo->write_u16(0x6017, 0, 0x64E6);  // the manual's 28 mm motor row
    sdo->write_u8(0x601B, 0, 1);
    sdo->write_i32(0x6003, 0, 1000);
    sdo->write_u32(0x6004, 0, 5000);
    advance(0.5);
    sim->set_jammed(true);
    advance(0.1);
    EXPECT_EQ(sdo->read_u8(0x6001, 0) & st::kStall, st::kStall);
    EXPECT_FALSE(sim->busy());
    sim->set_jammed(false);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x6004, 0, 10); }), 0x08000022u);
    sdo->write_u8(0x6001, 0, 0x0F);  // busy cannot be cleared, the stall bit can
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 0);
    EXPECT_GE(sim->emcy_sent(), 1u);
}

TEST_F(SimFixture, ExternalStopEdgeAndDebounce) {
    sdo->write_u8(0x600F, 1, 0x01);  // EXT1 enabled, falling edge
    sdo->write_u16(0x601A, 0, 50);   // 50 ms debounce
    sdo->write_i32(0x6003, 0, 1000);
    sdo->write_u32(0x6004, 0, 100000);
    advance(1);
    sim->set_input(port::kExt1, false);  // falling...
    advance(0.02);
    sim->set_input(port::kExt1, true);   // ...a 20 ms glitch does not count
    advance(0.1);
    EXPECT_TRUE(sim->busy());
    sim->set_input(port::kExt1, false);
    advance(0.049);
    EXPECT_TRUE(sim->busy());
    advance(0.002);
    EXPECT_FALSE(sim->busy());
    EXPECT_EQ(sdo->read_u8(0x6001, 0), st::kExt1);
    EXPECT_EQ(sdo->read_u16(0x6012, 0) & (1u << port::kExt1), 1u << port::kExt1);  // low reads 1
    sim->set_input(port::kExt2, false);  // EXT2 not enabled: no effect
    advance(1);
    EXPECT_EQ(sdo->read_u8(0x6001, 0), st::kExt1);
}

TEST_F(SimFixture, GpioInvertedPolarity) {
    sdo->write_u16(0x6011, 1, 0x0783);  // GPIO1, GPIO2 outputs; bits 7-10 ignored
    EXPECT_EQ(sdo->read_u16(0x6011, 1), 0x0003);
    sdo->write_u16(0x6012, 0, 0x0003);  // E-P12: 03 00 = GPIO1 and GPIO2 low [D]
    EXPECT_EQ(sdo->read_u16(0x6012, 0), 0x0003);
    sim->set_input(2, false);  // an input pulled low reads 1
    EXPECT_EQ(sdo->read_u16(0x6012, 0), 0x0007);
}

// ---- persistence ------------------------------------------------------------------------

TEST_F(SimFixture, RomSurvivesSaveAndResetNode) {
    sdo->write_u16(0x6006, 0, 123);  // ROM
    sdo->write_u8(0x6005, 0, 1);     // RAM
    sdo->write_u8(0x2002, 0, 9);
    // Reset node without saving: lost.
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x81, 5}));
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(sdo->read_u16(0x6006, 0), 400);
    sdo->write_u16(0x6006, 0, 123);
    sdo->write_u8(0x6005, 0, 1);
    sdo->write_u8(0x2007, 0, 2);  // save
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x81, 5}));
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(sdo->read_u16(0x6006, 0), 123);
    EXPECT_EQ(sdo->read_u8(0x6005, 0), 0);
    sdo->write_u8(0x2007, 0, 3);  // factory values into RAM only (C-P19)
    EXPECT_EQ(sdo->read_u16(0x6006, 0), 400);
    sim->power_cycle();
    EXPECT_EQ(sdo->read_u16(0x6006, 0), 123);
}

TEST_F(SimFixture, PositionSavedAtPowerLossWith602A) {
    sdo->write_i32(0x600C, 0, 777);
    sim->power_cycle();
    EXPECT_EQ(sdo->read_i32(0x600C, 0), 0);
    sdo->write_u8(0x602A, 0, 1);
    sdo->write_u8(0x2007, 0, 2);
    sdo->write_i32(0x600C, 0, 777);
    sim->power_cycle();
    EXPECT_EQ(sdo->read_i32(0x600C, 0), 777);
    EXPECT_EQ(sdo->read_i32(0x6022, 0), 777);
}

// ---- PDO ------------------------------------------------------------------------------------

TEST_F(SimFixture, MappingOnlyWhatAppendix1Allows) {
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x1A00, 1, 0x60040020); }), 0x06040041u);
    EXPECT_EQ(abort_of([&] { sdo->write_u32(0x1A00, 1, 0x60060010); }), 0x06040041u);
    // E-P06..E-P11 as-is (B-P32).
    sdo->write_u32(0x1800, 1, 0x187);
    sdo->write_u8(0x1800, 2, 0xFF);
    sdo->write_u16(0x1800, 3, 0x32);
    sdo->write_u16(0x1800, 5, 1000);
    sdo->write_u8(0x1A00, 0, 1);
    sdo->write_u32(0x1A00, 1, 0x60120010);
    EXPECT_EQ(sdo->read_u32(0x1A00, 1), 0x60120010u);
    EXPECT_EQ(abort_of([&] { sdo->write_u8(0x1800, 2, 241); }), 0x06090030u);
}

// ---- offline program ----------------------------------------------------------------------

TEST_F(SimFixture, ProgramUploadRunsOnTheClock) {
    auto words = assemble("VSET 0,1000\nDIR 0,1\nROT 0,1000\nWAIT 1,0\nCNTI\nCMP 1,2\nJNE 0,2\nOUT 1,1\n");
    for (std::size_t i = 0; i < words.size(); ++i) {
        sdo->write_u8(0x6019, 1, static_cast<std::uint8_t>(i));
        sdo->write_u32(0x6019, 2, words[i]);
    }
    for (std::size_t i = 0; i < words.size(); ++i) {
        sdo->write_u8(0x6019, 1, static_cast<std::uint8_t>(i));
        EXPECT_EQ(sdo->read_u32(0x6019, 2), words[i]);
    }
    sdo->write_u8(0x6018, 1, static_cast<std::uint8_t>(words.size()));
    sdo->write_u8(0x6019, 3, 1);  // write to flash
    EXPECT_EQ(sim->flash_program(), words);
    sdo->write_u8(0x6018, 2, 1);  // offline exec
    advance(0.5);
    EXPECT_EQ(sim->position(), 500);
    advance(0.6);  // first move ends at 1.0 s, the second starts at once
    EXPECT_EQ(sim->position(), 1100);
    advance(1.0);
    EXPECT_EQ(sim->position(), 2000);
    EXPECT_FALSE(sim->program_running());
    EXPECT_EQ(sim->program_counter_value(), 2u);
    EXPECT_EQ(sim->gpio_value() & 1u, 1u);  // OUT 1,1: GPO1 low
    // Auto-run after power-up once saved.
    sdo->write_u8(0x2007, 0, 2);
    sim->power_cycle();
    EXPECT_TRUE(sim->program_running());
}

TEST_F(SimFixture, NmtStoppedSilencesSdo) {
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x02, 5}));
    std::this_thread::sleep_for(30ms);
    canopen::SdoClient quick(*host, 5, {.timeout = 100ms});
    EXPECT_THROW(quick.read_u8(0x6001, 0), canopen::SdoTimeout);
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x80, 5}));
    std::this_thread::sleep_for(30ms);
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 0);
}

// B-P36 / B-P27: 2002h is a RAM copy until reset communication, then the node
// answers under the new ID (boot-up 0x709) with its predefined COB-IDs moved;
// unsaved, a reset node brings the flash value (5) back.
TEST_F(SimFixture, NodeIdTakesEffectAtResetCommunication) {
    sdo->write_u8(0x2002, 0, 9);
    EXPECT_EQ(sdo->read_u8(0x2002, 0), 9);
    EXPECT_EQ(sim->node_id(), 5);
    auto boot = host->recv(std::chrono::milliseconds(0));  // drain
    while (boot) boot = host->recv(std::chrono::milliseconds(0));
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x82, 5}));
    bool seen = false;
    for (int i = 0; i < 100 && !seen; ++i) {
        auto f = host->recv(std::chrono::milliseconds(20));
        seen = f && f->id == 0x709 && f->len == 1 && f->data[0] == 0;
    }
    EXPECT_TRUE(seen);
    for (int i = 0; i < 100 && sim->node_id() != 9; ++i) std::this_thread::sleep_for(5ms);
    canopen::SdoClient at9(*host, 9);
    EXPECT_EQ(at9.read_u32(0x1800, 1), 0x189u);
    EXPECT_EQ(at9.read_u32(0x1014, 0), 0x89u);
    canopen::SdoClient quick(*host, 5, {.timeout = 100ms});
    EXPECT_THROW(quick.read_u8(0x6001, 0), canopen::SdoTimeout);
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x81, 9}));  // reset node: flash says 5
    for (int i = 0; i < 200 && sim->node_id() != 5; ++i) std::this_thread::sleep_for(5ms);
    EXPECT_EQ(sim->node_id(), 5);
    EXPECT_EQ(sdo->read_u8(0x2002, 0), 5);
}

// B-P36 again, with the reset node sent the instant the new node's boot-up is on
// the bus: the new LocalNode answers from its constructor on, before the switch
// has finished, so the reset reaches it while the simulator still counts itself
// as node 5.  It used to take "2002h (5) == my ID (5)" for nothing to do and stay
// on 9; the switch must look again and come back to 5 (once seen under ASan).
TEST_F(SimFixture, ResetNodeRightAfterTheNewBootUpSwitchesBack) {
    sdo->write_u8(0x2002, 0, 9);
    std::atomic<bool> booted{false};
    // Sent from inside the delivery of the boot-up: on the thread still building the
    // new node, so the reset always lands before that thread has finished the switch.
    auto sub = host->subscribe_id(0x709, false, [&](const can::Frame& f) {
        if (f.len != 1 || f.data[0] != 0 || booted.exchange(true)) return;
        host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x81, 9}));  // flash still says 5
    });
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x82, 5}));
    for (int i = 0; i < 400 && !booted; ++i) std::this_thread::sleep_for(5ms);
    host->unsubscribe(sub);
    EXPECT_TRUE(booted.load());
    for (int i = 0; i < 400 && sim->node_id() != 5; ++i) std::this_thread::sleep_for(5ms);
    EXPECT_EQ(sim->node_id(), 5);
    EXPECT_EQ(sdo->read_u8(0x2002, 0), 5);
}

// B-P45: RESET_EN jumps to its target on a low pulse of GPI1 and stops the
// rotation; PAUSE_EN toggles pause on GPI2 without stopping an issued rotation.
TEST_F(SimFixture, ResetAndPauseInputs) {
    sdo->write_u16(0x601A, 0, 0);  // no debounce: edges act at once
    auto words = assemble("RESET_EN 1,5\nPAUSE_EN 1,0\nVSET 0,1000\nDIR 0,1\nROT 0,1000\nWAIT 1,0\nCNTI\nJMP 0,4\n");
    for (std::size_t i = 0; i < words.size(); ++i) {
        sdo->write_u8(0x6019, 1, static_cast<std::uint8_t>(i));
        sdo->write_u32(0x6019, 2, words[i]);
    }
    sdo->write_u8(0x6018, 1, static_cast<std::uint8_t>(words.size()));
    sdo->write_u8(0x6018, 2, 1);
    advance(0.5);
    EXPECT_EQ(sim->position(), 500);
    sim->set_input(1, false);  // GPI2 low: pause (the rotation goes on)
    sim->set_input(1, true);
    advance(1.0);
    EXPECT_EQ(sim->position(), 1000);
    EXPECT_EQ(sim->program_counter_value(), 0u);  // paused at WAIT's successor
    sim->set_input(1, false);  // resume
    sim->set_input(1, true);
    advance(0.25);
    EXPECT_EQ(sim->program_counter_value(), 1u);
    EXPECT_TRUE(sim->busy());
    const auto at_reset = sim->position();
    sim->set_input(0, false);  // GPI1 low: the rotation stops, pointer := 5 (WAIT 1,0)...
    // ...which passes at once (stopped), CNTI, JMP 0,4: a new ROT from where it stopped.
    EXPECT_EQ(sim->program_counter_value(), 2u);
    EXPECT_EQ(sim->program_pointer(), 5u);
    advance(0.5);
    EXPECT_EQ(sim->position(), at_reset + 500);
}

TEST_F(SimFixture, EmcyHistoryAndBootloader) {
    sim->inject_error(err::kAoc);
    sim->inject_error(err::kTsd);
    EXPECT_EQ(sdo->read_u8(0x1003, 0), 2);
    EXPECT_EQ(sdo->read_u32(0x1003, 1), 0x4200u);  // newest first
    EXPECT_EQ(sdo->read_u32(0x1003, 2), 0x2300u);
    sdo->write_u8(0x1003, 0, 0);
    EXPECT_EQ(sdo->read_u32(0x1003, 1), 0u);
    sdo->write_u8(0x2007, 0, 1);  // B-P39: bootloader, the application goes quiet
    for (int i = 0; i < 100 && !sim->in_bootloader(); ++i) std::this_thread::sleep_for(5ms);
    EXPECT_TRUE(sim->in_bootloader());
    canopen::SdoClient quick(*host, 5, {.timeout = 100ms});
    EXPECT_THROW(quick.read_u8(0x6001, 0), canopen::SdoTimeout);
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x01, 5}));  // #8: NMT start changes nothing
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x80, 0}));
    EXPECT_THROW(quick.read_u8(0x6001, 0), canopen::SdoTimeout);
    sim->power_cycle();
    EXPECT_FALSE(sim->in_bootloader());
    EXPECT_EQ(sdo->read_u8(0x6001, 0), 0);
}

// 1016h consumer: the manual documents no reaction to a lost heartbeat [P]:
// EMCY 8130h, no NMT state change (the motor is not stopped either).
TEST_F(SimFixture, LostConsumerHeartbeatOnlyEmcy) {
    sdo->write_u32(0x1016, 1, 0x00010032);  // node 1, 50 ms
    sdo->write_i32(0x6003, 0, 1000);
    sdo->write_u32(0x6004, 0, 100000);
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x01, 5}));
    std::uint8_t beat = 0x05;
    host->send(can::Frame::make(0x701, std::span(&beat, 1)));
    bool emcy = false;
    for (int i = 0; i < 100 && !emcy; ++i) {
        auto f = host->recv(std::chrono::milliseconds(20));
        emcy = f && f->id == 0x85 && f->data[0] == 0x30 && f->data[1] == 0x81;
    }
    EXPECT_TRUE(emcy);
    EXPECT_EQ(sim->node()->nmt_state(), canopen::NmtState::Operational);
    EXPECT_TRUE(sim->busy());
}

// SimOptions::store_path: the flash outlives the simulator object.
TEST(Pmc007Store, FlashSurvivesANewSimulator) {
    const std::string path = ::testing::TempDir() + "pmc007-store-test.flash";
    std::remove(path.c_str());
    SimClock clock;
    SimOptions o;
    o.store_path = path;
    {
        Sim sim(5, clock, o);
        auto& od = sim.od();
        std::uint8_t v[2] = {0x2C, 0x01};  // 300
        ASSERT_EQ(od.at(0x6006, 0)->remote_write(std::span(v, 2)), 0u);
        std::uint8_t save = 2;
        ASSERT_EQ(od.at(0x2007, 0)->remote_write(std::span(&save, 1)), 0u);
        std::uint8_t w[4] = {0x80, 0x0C, 0x00, 0x01};  // ROT 0,3200
        ASSERT_EQ(od.at(0x6019, 2)->remote_write(std::span(w, 4)), 0u);
        std::uint8_t one = 1;
        ASSERT_EQ(od.at(0x6019, 3)->remote_write(std::span(&one, 1)), 0u);
        std::uint8_t v2[2] = {0xF4, 0x01};  // 500, not saved
        ASSERT_EQ(od.at(0x6006, 0)->remote_write(std::span(v2, 2)), 0u);
    }
    Sim again(5, clock, o);
    EXPECT_EQ(again.od().at(0x6006, 0)->get_u64(), 300u);
    EXPECT_EQ(again.flash_program(), std::vector<std::uint32_t>{0x01000C80u});
    std::remove(path.c_str());
}

// reset_to_new() (the fuzz target reuses one sim): every object, the flash and
// the state read as on a sim newly built at the same time.
TEST(Pmc007SimReset, ResetToNewReadsAsAFreshSim) {
    SimClock clock{1'000'000'000};
    Sim used(5, clock);
    auto write = [&](std::uint16_t i, std::uint8_t s, std::vector<std::uint8_t> d) {
        canopen::VariablePtr v;
        ASSERT_EQ(used.od().lookup(i, s, v), 0);
        ASSERT_EQ(v->remote_write(d), 0u) << std::hex << i;
    };
    write(0x601A, 0, {50, 0});        // a ROM object...
    write(0x2007, 0, {2});            // ...saved to flash
    write(0x600C, 0, {0xD2, 0x04, 0, 0});  // position 1234
    used.inject_error(0x01);
    used.set_input(3, false);
    used.set_jammed(true);
    clock.advance(300'000'000);
    used.poll();
    ASSERT_NE(used.error_status(), 0);
    used.reset_to_new();
    Sim fresh(5, clock);
    for (const auto& r : od_rows())
        EXPECT_EQ(used.od().at(r.index, r.sub)->get(), fresh.od().at(r.index, r.sub)->get())
            << std::hex << r.index << ":" << int(r.sub);
    EXPECT_EQ(used.error_status(), fresh.error_status());
    EXPECT_EQ(used.controller_status(), fresh.controller_status());
    EXPECT_EQ(used.position(), fresh.position());
    EXPECT_EQ(used.gpio_value(), fresh.gpio_value());
    EXPECT_EQ(used.flash_program(), fresh.flash_program());
    // The flash is factory again: a power cycle does not bring back the saved 601Ah.
    used.power_cycle();
    EXPECT_EQ(used.od().at(0x601A, 0)->get(), fresh.od().at(0x601A, 0)->get());
}

// A closed simulator keeps its dictionary: a power cycle (or a write) after close()
// reaches the heartbeat and PDO hooks of services that are gone (a use-after-free
// under ASan before the hooks held their service weakly).
TEST(Pmc007SimLifetime, PowerCycleAfterCloseTouchesNoClosedService) {
    SimClock clock{1'000'000'000};
    auto dev = can::open_virtual("pmc007-lifetime");
    auto sim = std::make_unique<Sim>(5, clock);
    sim->attach(dev);
    sim->close();
    sim->power_cycle();                                          // reloads 1016h/1017h/PDO values
    const std::uint8_t period[2] = {0x64, 0x00};
    EXPECT_EQ(sim->od().at(0x1017, 0)->remote_write(period), 0u);   // a write through the hooks
    EXPECT_EQ(sim->od().at(0x1800, 5)->remote_write(period), 0u);
    EXPECT_EQ(sim->od().at(0x1017, 0)->get_u64(), 0x64u);
    sim->attach(dev);                                           // and it serves again
    sim->close();
}

// B-P36 [P]: a node-ID written to 2002h that another node already serves on the bus
// is not taken: the node stays on its old ID, and last_error() says why (it used to be
// silence, and any other failure of the switch was silenced as "taken" too).
TEST_F(SimFixture, NodeIdSwitchToATakenIdStaysAndSaysWhy) {
    Sim other(9, clock);
    other.attach(can::open_virtual(hub));
    EXPECT_EQ(sim->last_error(), "");
    sdo->write_u8(0x2002, 0, 9);
    host->send(can::Frame::make(0, std::vector<std::uint8_t>{0x82, 5}));  // reset communication
    for (int i = 0; i < 400 && sim->last_error().empty(); ++i) std::this_thread::sleep_for(5ms);
    EXPECT_EQ(sim->last_error(), "pmc007 sim node 5: node-ID 9 is taken, stays on 5");
    EXPECT_EQ(sim->node_id(), 5);
    EXPECT_EQ(sdo->read_u8(0x2002, 0), 9);  // node 5 still answers; the RAM value stays what was written
    other.close();
}
