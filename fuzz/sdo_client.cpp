// Fuzz the SDO client state machine: a transfer of each kind started, then
// any response frames (any length 0..8) and timer ticks.  Invariants: the
// upload never grows past max_transfer (+ one block segment), at most one
// sub-block of output per frame, and every transfer ends Done/Failed/Running.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "motorbus/canopen/sdo_client.hpp"

using namespace motorbus;
using namespace motorbus::canopen;

namespace {
// Frames and ticks looked at per input: a longer input only runs more
// transfers one after another, each from a fresh start.
constexpr std::size_t kMaxSteps = 256;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 2) return 0;
    SdoClientConfig cfg;
    cfg.max_transfer = 2048;
    cfg.block_size = static_cast<std::uint8_t>(1 + data[0] % 127);
    SdoClientMachine cli(cfg);
    SdoClientMachine::Outbox out;
    Nanos now = 0;
    Bytes payload(static_cast<std::size_t>(data[1]) * 3, 0x5A);
    auto start = [&](std::uint8_t how) {
        out.clear();
        switch (how % 5) {
            case 0: cli.start_upload(0x2000, 1, TransferMode::Auto, now, out); break;
            case 1: cli.start_upload(0x2000, 1, TransferMode::Block, now, out); break;
            case 2: cli.start_download(0x2000, 1, payload, TransferMode::Auto, now, out); break;
            case 3: cli.start_download(0x2000, 1, payload, TransferMode::Segmented, now, out); break;
            default: cli.start_download(0x2000, 1, payload, TransferMode::Block, now, out); break;
        }
    };
    start(data[1]);
    std::size_t i = 2;
    std::size_t steps = 0;
    while (i < size && steps++ < kMaxSteps) {
        const std::uint8_t hdr = data[i++];
        if (!cli.busy()) {
            if (cli.status() == SdoClientMachine::Status::Failed && !cli.error()) std::abort();
            cli.reset();
            start(hdr);
            continue;
        }
        if (hdr == 0xFF) {
            now += 800'000'000;
            out.clear();
            cli.on_timer(now, out);
            if (out.size() > 1) std::abort();
            continue;
        }
        now += (hdr >> 4) * 10'000'000;
        const std::size_t len = std::min<std::size_t>(hdr % 9, size - i);
        out.clear();
        cli.on_frame(std::span(data + i, len), now, out);
        i += len;
        if (out.size() > 127) std::abort();
        if (cli.result().size() > cfg.max_transfer + 7) std::abort();
    }
    return 0;
}
