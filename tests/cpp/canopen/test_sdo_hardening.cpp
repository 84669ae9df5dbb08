// Hardening: SDO block upload over the virtual bus with one of the client's
// frames dropped (fault injection drop_every = n), for several sizes.  Every
// client frame after the initiate can be lost once: the start command, any
// sub-block acknowledgement, the final one; the client must recover (CiA 301:
// the acknowledged sequence number tells the server what to resend).
#include <gtest/gtest.h>

#include <atomic>
#include <string>

#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using namespace std::chrono_literals;

using motorbus::test::pattern;

namespace {

std::string fresh_hub() {
    static std::atomic<int> n{0};
    return "sdo-hardening-" + std::to_string(n++);
}

struct Case {
    std::size_t size;
    unsigned drop_every;
};

class BlockUploadLoss : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(BlockUploadLoss, RecoversFromADroppedClientFrame) {
    const auto [size, n] = GetParam();
    const std::string hub = fresh_hub();
    auto dev = can::open_virtual(hub, {});
    auto host = can::open_virtual(hub, {});
    auto od = std::make_shared<ObjectDictionary>();
    od->add_variable({.index = 0x2201, .name = "Blob", .type = DataType::Domain, .access = Access::RW,
                      .max_size = 1 << 20});
    const Bytes data = pattern(size);
    od->at(0x2201, 0)->set(data);
    LocalNode node(*dev, 5, od);
    SdoClientOptions o;
    o.timeout = 200ms;  // the sub-block timer fires after 140 ms
    o.block_size = 4;
    SdoClient sdo(*host, 5, o);
    can::FaultOptions f;
    f.drop_every = n;  // counts the client's frames from here: initiate = 1
    host->set_faults(f);
    Bytes got;
    ASSERT_NO_THROW(got = sdo.upload(0x2201, 0, TransferMode::Block))
        << size << " bytes, client frame every " << n << " dropped";
    EXPECT_EQ(got, data);
    EXPECT_GE(host->counters().tx_dropped, 1u);
    host->set_faults({});
}

INSTANTIATE_TEST_SUITE_P(Sizes, BlockUploadLoss,
                         ::testing::Values(Case{3, 2}, Case{3, 3}, Case{20, 2}, Case{20, 3}, Case{60, 2},
                                           Case{60, 3}, Case{60, 4}, Case{60, 5}, Case{200, 3},
                                           Case{200, 4}, Case{200, 6}, Case{889, 7}),
                         [](const auto& info) {
                             return "size" + std::to_string(info.param.size) + "_drop" +
                                    std::to_string(info.param.drop_every);
                         });
