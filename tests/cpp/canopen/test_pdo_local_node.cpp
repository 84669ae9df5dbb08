// The PDO engine on a LocalNode, configured over the bus by the SdoClient:
// the whole PMC007 example end to end on the virtual bus.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <sstream>
#include <thread>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/canopen/sdo_client_access.hpp"
#include "motorbus/canopen/abort_codes.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

namespace {

Bytes payload(const can::Frame& f) {
    auto p = f.payload();
    return {p.begin(), p.end()};
}

std::vector<std::pair<std::uint32_t, Bytes>> pmc007_frames() {
    std::ifstream in(std::string(MOTORBUS_TEST_DATA) + "/vectors/seed_examples.json");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    auto start = s.find("\"pdo_config_sequence\"");
    std::string part = s.substr(start, s.find("\"accel_gears_pps2\"", start) - start);
    std::vector<std::pair<std::uint32_t, Bytes>> out;
    const std::string idk = "\"id\": \"", datak = "\"data\": \"";
    for (auto p = part.find(idk); p != std::string::npos; p = part.find(idk, p + 1)) {
        const auto ib = p + idk.size();
        const auto d = part.find(datak, ib);
        if (d == std::string::npos) break;
        const auto db = d + datak.size();
        Bytes b;
        std::istringstream hs(part.substr(db, part.find('"', db) - db));
        std::string tok;
        while (hs >> tok) b.push_back(static_cast<std::uint8_t>(std::stoul(tok, nullptr, 16)));
        out.emplace_back(std::stoul(part.substr(ib, part.find('"', ib) - ib), nullptr, 16), b);
    }
    return out;
}

std::shared_ptr<ObjectDictionary> pmc007_od() {
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x1000, .name = "Device type", .type = DataType::Unsigned32,
                      .access = Access::RO, .default_value = std::uint64_t{0}});
    od->add_variable({.index = 0x6012, .name = "GPIO value", .type = DataType::Unsigned16,
                      .access = Access::RW, .pdo_mappable = true, .default_value = std::uint64_t{0x0003}});
    od->add_variable({.index = 0x6040, .name = "Controlword", .type = DataType::Unsigned16,
                      .access = Access::RW, .pdo_mappable = true, .default_value = std::uint64_t{0}});
    return od;
}

// Collects frames with a given id from a sniffer endpoint.
std::vector<can::Frame> collect(can::Bus& b, std::uint32_t id, std::size_t n, std::chrono::milliseconds t) {
    std::vector<can::Frame> out;
    const auto deadline = std::chrono::steady_clock::now() + t;
    while (out.size() < n && std::chrono::steady_clock::now() < deadline) {
        auto f = b.recv(5ms);
        if (f && f->id == id) out.push_back(*f);
    }
    return out;
}

}  // namespace

TEST(PdoLocalNode, Pmc007ConfigurationEndToEnd) {
    const auto vec = pmc007_frames();
    ASSERT_EQ(vec.size(), 7u);
    auto dev_bus = can::open_virtual("svc-pmc007");
    auto host_bus = can::open_virtual("svc-pmc007");
    auto sniff = can::open_virtual("svc-pmc007");
    auto od = pmc007_od();
    LocalNode node(*dev_bus, 5, od);
    auto pdo = PdoService::attach(node, {.strict = false});
    BusSdoAccess sdo(*host_bus);
    PdoConfig c;
    c.cob_id = 0x187;
    c.transmission_type = 255;
    c.inhibit_100us = 50;
    c.event_timer_ms = 1000;
    c.mapping = std::vector<PdoMapEntry>{{0x6012, 0, 16}};
    write_pdo(sdo, 5, c, PdoProcedure::Direct);
    // The SDO requests on the wire are the manual's, byte for byte.
    std::vector<can::Frame> reqs;
    while (auto f = sniff->recv(20ms)) {
        if (f->id == 0x605) reqs.push_back(*f);
        if (reqs.size() == 6) break;
    }
    ASSERT_EQ(reqs.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(payload(reqs[i]), vec[i].second) << i;
    // The node's dictionary holds the new configuration.
    EXPECT_EQ(od->at(0x1800, 1)->get_u64(), 0x187u);
    EXPECT_EQ(od->at(0x1A00, 1)->get_u64(), 0x60120010u);
    EXPECT_EQ(pdo->engine().mapping(true, 1), (std::vector<PdoMapEntry>{{0x6012, 0, 16}}));
    // NMT start: the TPDO goes out as 187 03 00.
    NmtMaster nmt(*host_bus);
    nmt.start(5);
    auto tp = collect(*sniff, 0x187, 1, 2000ms);
    ASSERT_EQ(tp.size(), 1u);
    EXPECT_EQ(payload(tp[0]), vec[6].second);
    // A change of the GPIO value goes out as an event.
    od->at(0x6012, 0)->set_u64(0x0002);
    tp = collect(*sniff, 0x187, 1, 2000ms);
    ASSERT_EQ(tp.size(), 1u);
    EXPECT_EQ(payload(tp[0]), (Bytes{0x02, 0x00}));
    node.close();
}

TEST(PdoLocalNode, StrictNodeAbortsOverSdoAndCia301ProcedureWorks) {
    auto dev_bus = can::open_virtual("svc-strict");
    auto host_bus = can::open_virtual("svc-strict");
    auto od = pmc007_od();
    LocalNode node(*dev_bus, 5, od);
    auto pdo = PdoService::attach(node);
    BusSdoAccess sdo(*host_bus);
    PdoConfig c;
    c.cob_id = 0x187;
    c.transmission_type = 255;
    c.mapping = std::vector<PdoMapEntry>{{0x6012, 0, 16}};
    try {
        write_pdo(sdo, 5, c, PdoProcedure::Direct);
        FAIL() << "a strict node must refuse a COB-ID change while valid";
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06090030u);  // P9 over the wire
    }
    // Unmappable object through the real SDO path: P7.
    try {
        PdoConfig bad = c;
        bad.mapping = std::vector<PdoMapEntry>{{0x1000, 0, 32}};
        write_pdo(sdo, 5, bad, PdoProcedure::Cia301);
        FAIL();
    } catch (const SdoAbortError& e) {
        EXPECT_EQ(e.code, 0x06040041u);
    }
    write_pdo(sdo, 5, c, PdoProcedure::Cia301);
    auto back = read_pdo(sdo, 5, true, 1);
    EXPECT_EQ(*back.cob_id, 0x187u);
    EXPECT_TRUE(back.enabled);
    EXPECT_EQ(*back.mapping, (std::vector<PdoMapEntry>{{0x6012, 0, 16}}));
    // RPDO into the controlword over the bus.
    PdoConfig r;
    r.tpdo = false;
    r.number = 1;
    r.transmission_type = 255;
    r.mapping = std::vector<PdoMapEntry>{{0x6040, 0, 16}};
    write_pdo(sdo, 5, r, PdoProcedure::Cia301);
    NmtMaster nmt(*host_bus);
    nmt.start(5);
    PdoSender tx(*host_bus, 0x205, {{0x6040, 0, 16}});
    std::uint64_t v[] = {0x000F};
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    while (od->at(0x6040, 0)->get_u64() != 0x000F && std::chrono::steady_clock::now() < deadline) {
        tx.send(v);
        std::this_thread::sleep_for(2ms);
    }
    EXPECT_EQ(od->at(0x6040, 0)->get_u64(), 0x000Fu);
    node.close();
}

// Node 5 serving `od` on a virtual bus, its TPDO 1 written to `c` by SDO and the node
// started; a host endpoint and a sniffer on the same bus.
struct StartedNode {
    std::shared_ptr<can::VirtualBus> dev_bus, host_bus, sniff;
    std::unique_ptr<LocalNode> node;
    std::shared_ptr<PdoService> pdo;
    StartedNode(const char* bus_name, std::shared_ptr<ObjectDictionary> od, const PdoConfig& c)
        : dev_bus(can::open_virtual(bus_name)), host_bus(can::open_virtual(bus_name)),
          sniff(can::open_virtual(bus_name)), node(std::make_unique<LocalNode>(*dev_bus, 5, std::move(od))),
          pdo(PdoService::attach(*node)) {
        BusSdoAccess sdo(*host_bus);
        write_pdo(sdo, 5, c, PdoProcedure::Cia301);
        NmtMaster nmt(*host_bus);
        nmt.start(5);
    }
    ~StartedNode() { node->close(); }
};

// A TPDO reads its objects as an SDO upload does: through the read hook (a simulator's live
// value), and the stored value where the hook refuses.
TEST(PdoLocalNode, TpdoCarriesWhatTheReadHookAnswers) {
    auto od = pmc007_od();
    std::atomic<std::uint16_t> live{0x1234};
    std::atomic<bool> refuse{false};
    od->at(0x6012, 0)->set_read_hook([&](const Variable&, Bytes& value) -> std::uint32_t {
        if (refuse) return abort_code::kGeneral;
        const std::uint16_t v = live;
        value = {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)};
        return 0;
    });
    PdoConfig c;
    c.transmission_type = 1;  // on every SYNC
    c.mapping = std::vector<PdoMapEntry>{{0x6012, 0, 16}};
    StartedNode n("svc-hook", od, c);
    std::this_thread::sleep_for(20ms);
    can::Frame sync;
    sync.id = 0x080;
    sync.len = 0;
    auto tpdo_after_sync = [&] {
        n.host_bus->send(sync);
        auto got = collect(*n.sniff, 0x185, 1, 2000ms);
        return got.empty() ? Bytes{} : payload(got[0]);
    };
    EXPECT_EQ(tpdo_after_sync(), (Bytes{0x34, 0x12}));
    live = 0xBEEF;
    EXPECT_EQ(tpdo_after_sync(), (Bytes{0xEF, 0xBE}));
    refuse = true;
    EXPECT_EQ(tpdo_after_sync(), (Bytes{0x03, 0x00}));  // the stored default
}

// A read hook that sets a mapped object as it answers (the PMC007 simulator
// publishes its whole state on each read) once deadlocked the engine on its own
// mutex (the TPDO was built under it), and without the re-entry guard an
// event-driven TPDO would fire again for the value its own reading set, for ever.
TEST(PdoLocalNode, AReadHookThatSetsAMappedObjectSendsEachEventTpdoOnce) {
    auto od = pmc007_od();
    auto other = od->at(0x6040, 0);
    std::atomic<int> reads{0};
    od->at(0x6012, 0)->set_read_hook([&](const Variable&, Bytes& value) -> std::uint32_t {
        const int n = ++reads;
        const std::uint8_t b[2] = {static_cast<std::uint8_t>(n), 0};
        other->set(std::span<const std::uint8_t>(b, 2));  // notifies the PDO engine
        value = {b[0], 0};
        return 0;
    });
    PdoConfig c;
    c.transmission_type = 254;  // event-driven: a change of a mapped object is an event
    c.event_timer_ms = 20;
    c.mapping = std::vector<PdoMapEntry>{{0x6012, 0, 16}, {0x6040, 0, 16}};
    StartedNode n("svc-hook-set", od, c);
    auto got = collect(*n.sniff, 0x185, 100, 300ms);
    // About one per 20 ms timer tick: never a storm, never none.
    EXPECT_GE(got.size(), 5u);
    EXPECT_LE(got.size(), 25u);
    EXPECT_LE(reads.load(), static_cast<int>(got.size()) + 1);
}
