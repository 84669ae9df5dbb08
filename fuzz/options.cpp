// libFuzzer: option validation (hardening defect 1).  Arbitrary bytes become
// the fields of one options struct (sizes, counts, probabilities, durations,
// names — including 0, huge, negative, NaN and inf); check_options() must
// either refuse with InvalidArgument or accept, and whatever it accepts must
// then work: a parser built with the accepted bound, an SLCAN identity that
// answers V/N with exactly one reply, and (for inputs that ask for it) a pair
// of live virtual-bus endpoints that send, receive and close without hanging
// or corrupting memory.  rx_queue_size = 0 corrupting the heap is the kind of
// bug this catches: the accepted-options path runs under ASan.
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>

#include "motorbus/can/slcan_bus.hpp"
#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/can/slcan_server.hpp"
#include "motorbus/can/socketcand_bus.hpp"
#include "motorbus/can/socketcand_codec.hpp"
#include "motorbus/can/socketcand_server.hpp"
#include "motorbus/can/virtual_bus.hpp"
#include "motorbus/errors.hpp"

using namespace motorbus;
using namespace motorbus::can;

namespace {

// Reads typed values from the input; past its end every read gives 0.
class Input {
public:
    Input(const std::uint8_t* data, std::size_t size) : p_(data), n_(size) {}
    std::uint8_t u8() { return i_ < n_ ? p_[i_++] : 0; }
    std::uint64_t raw64() {
        std::uint64_t v = 0;
        for (int k = 0; k < 8; ++k) v = (v << 8) | u8();
        return v;
    }
    // Sizes: mostly the interesting small values, sometimes anything.
    std::size_t size() {
        std::uint8_t sel = u8();
        if (sel < 200) return sel % 8;  // 0..7: the edges that matter
        if (sel < 250) return raw64() % 100000;
        return static_cast<std::size_t>(raw64());
    }
    double real() {
        std::uint8_t sel = u8();
        if (sel < 64) return static_cast<double>(sel) / 32.0 - 0.5;  // around [0, 1]
        std::uint64_t bits = raw64();
        double d;
        std::memcpy(&d, &bits, sizeof d);  // any double: NaN, inf, denormals
        return d;
    }
    Duration duration() {
        std::uint8_t sel = u8();
        if (sel < 128) return std::chrono::microseconds(static_cast<int>(sel) - 64);
        return Duration(static_cast<std::int64_t>(raw64()));
    }
    std::string text(std::size_t max) {
        std::string s;
        std::size_t len = u8() % (max + 1);
        for (std::size_t k = 0; k < len; ++k) s.push_back(static_cast<char>(u8()));
        return s;
    }
    std::span<const std::uint8_t> rest() { return {p_ + i_, n_ - std::min(i_, n_)}; }

private:
    const std::uint8_t* p_;
    std::size_t n_;
    std::size_t i_ = 0;
};

template <class F>
bool accepted(F&& check) {
    try {
        check();
        return true;
    } catch (const InvalidArgument&) {
        return false;  // any other exception escapes and is a finding
    }
}

void bus_options(Input& in, BusOptions& o) {
    o.rx_queue_size = in.size();
    o.receive_own = in.u8() & 1;
}

// Accepted virtual options, used for real: two endpoints of one hub exchange a
// few frames with zero timeouts (nothing may block), then close with frames
// still queued or delayed (close must not wait for them).
void exercise_virtual(const VirtualOptions& o, Input& in) {
    if (o.rx_queue_size > (1u << 16) || o.tx_queue > (1u << 16)) return;  // bounds, not allocations: skip the slow path
    auto a = open_virtual("fuzz-options", o);
    auto b = open_virtual("fuzz-options", o);
    const int frames = in.u8() % 8;
    for (int k = 0; k < frames; ++k) {
        try {
            const std::uint8_t payload[1] = {static_cast<std::uint8_t>(k)};
            a->send(Frame::make(static_cast<std::uint32_t>(k), payload), Duration::zero());
        } catch (const TimeoutError&) {
            // tx queue full at zero timeout: the documented answer
        } catch (const LinkDown&) {
        }
    }
    auto got = b->recv_many(64, Duration::zero());
    if (got.size() > static_cast<std::size_t>(frames)) std::abort();  // nothing invented
    if (got.size() > o.rx_queue_size) std::abort();                     // the queue bound holds
    a->close();
    b->close();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Input in(data, size);
    switch (in.u8() % 6) {
        case 0: {
            VirtualOptions o;
            bus_options(in, o);
            o.bitrate = in.real() * 1e6;
            o.tx_queue = in.size();
            o.faults.drop_every = in.u8();
            o.faults.drop_probability = in.real();
            o.faults.corrupt_probability = in.real();
            o.faults.delay_ns = static_cast<Nanos>(in.duration().count());
            o.rx_spin = std::chrono::microseconds(in.u8() % 50);
            const bool live = in.u8() & 1;
            if (accepted([&] { check_options(o); }) && live) exercise_virtual(o, in);
            break;
        }
        case 1: {
            SocketcandOptions o;
            bus_options(in, o);
            o.connect_timeout = in.duration();
            o.handshake_timeout = in.duration();
            o.keepalive_period = in.duration();
            o.keepalive_misses = static_cast<int>(static_cast<std::int8_t>(in.u8()));
            o.tx_buffer_bytes = in.size();
            o.max_element = in.size() + (in.u8() & 1 ? 60 : 0);
            if (!accepted([&] { check_options(o); })) break;
            // The accepted bound parses: elements up to max_element arrive, longer ones are dropped.
            socketcand::ElementParser parser(o.max_element);
            auto rest = in.rest();
            parser.feed(std::span(reinterpret_cast<const char*>(rest.data()), rest.size()),
                        [&](const socketcand::Element&) {}, [](const socketcand::ParseError&) {});
            break;
        }
        case 2: {
            SocketcandServerOptions o;
            o.channel = in.text(20);
            o.max_clients = in.size();
            o.client_queue = in.size();
            o.idle_timeout = in.duration();
            o.element_timeout = in.duration();
            o.open_timeout = in.duration();
            o.bus_send_budget = in.duration();
            o.max_element = in.size() + (in.u8() & 1 ? 60 : 0);
            o.socket_send_buffer = static_cast<int>(static_cast<std::int32_t>(in.raw64()));
            if (!accepted([&] { check_options(o); })) break;
            // An accepted channel is one a client can open.
            if (!o.channel.empty()) socketcand::check_channel_name(o.channel, "channel");
            if (o.max_clients == 0 || o.client_queue == 0) std::abort();
            break;
        }
        case 3: {
            SlcanServerOptions o;
            o.queue_size = in.size();
            o.identity.version = in.text(8);
            o.identity.serial = in.text(8);
            o.bus_send_timeout = in.duration();
            o.write_timeout = in.duration();
            if (!accepted([&] { check_options(o); })) break;
            // The accepted identity answers V and N with exactly the identity and a CR.
            slcan::AdapterSession session(o.identity);
            for (const char* cmd : {"V", "N"}) {
                auto r = session.handle(slcan::parse_command(cmd));
                const std::string& want = cmd[0] == 'V' ? o.identity.version : o.identity.serial;
                if (r.bytes != want + "\r") std::abort();
                if (r.bytes.find('\r') != r.bytes.size() - 1) std::abort();
            }
            break;
        }
        case 4: {
            SlcanOptions o;
            o.bitrate = static_cast<unsigned>(in.raw64());
            if (in.u8() & 1) o.btr = static_cast<std::uint16_t>(in.raw64());
            o.tx_window = in.size();
            o.ack_timeout = in.duration();
            o.open_timeout = in.duration();
            o.status_poll = in.duration();
            o.partial_line_timeout = in.duration();
            o.echo_window = in.duration();
            o.tx_coalesce = in.duration();
            o.reconnect_min = in.duration();
            o.reconnect_max = in.duration();
            bus_options(in, o.bus);
            if (!accepted([&] { check_options(o); })) break;
            // An accepted rate without BTR is 0 (keep) or one with an Sn code.
            if (o.bitrate != 0 && !o.btr && !slcan::bitrate_code(o.bitrate)) std::abort();
            if (o.tx_window == 0 || o.reconnect_min > o.reconnect_max) std::abort();
            break;
        }
        default: {
            FaultOptions f;
            f.drop_probability = in.real();
            f.corrupt_probability = in.real();
            f.delay_ns = static_cast<Nanos>(in.duration().count());
            if (!accepted([&] { check_options(f); })) break;
            if (!(f.drop_probability >= 0 && f.drop_probability <= 1)) std::abort();
            if (!(f.corrupt_probability >= 0 && f.corrupt_probability <= 1)) std::abort();
            break;
        }
    }
    return 0;
}
