#include "motorbus/can/slcan_server.hpp"

#include <array>

#include "motorbus/errors.hpp"

namespace motorbus::can {

using slcan::Command;
using slcan::CommandKind;

namespace {
// `V1013` / `NMB01`: the command letter then 4 printable characters; anything
// else would break the reply framing (a CR) or what SLCAN tools parse.
void check_identity_field(const std::string& value, char letter, const char* field) {
    bool ok = value.size() == 5 && value[0] == letter;
    for (std::size_t i = 1; ok && i < value.size(); ++i)
        ok = value[i] > 0x20 && value[i] < 0x7F;
    if (!ok)
        throw InvalidArgument(std::string("SlcanServer ") + field + ": '" + value + "', must be '" + letter +
                              "' followed by 4 printable characters (the adapter's reply)");
}
}  // namespace

void check_options(const SlcanServerOptions& o) {
    if (o.queue_size == 0) throw InvalidArgument("SlcanServer queue_size: must be >= 1");
    if (o.bus_send_timeout.count() < 0) throw InvalidArgument("SlcanServer bus_send_timeout: must be >= 0");
    if (o.write_timeout.count() < 0) throw InvalidArgument("SlcanServer write_timeout: must be >= 0");
    check_identity_field(o.identity.version, 'V', "version");
    check_identity_field(o.identity.serial, 'N', "serial_number");
}

SlcanServer::SlcanServer(std::shared_ptr<Bus> bus, SlcanServerOptions options)
    : bus_(std::move(bus)), opts_(std::move(options)), session_(opts_.identity) {
    if (!bus_) throw InvalidArgument("SlcanServer: no bus");
    pty_ = std::make_unique<serial::PtyPair>();
    port_ = pty_->port();
    pty_path_ = pty_->slave_path();
    start();
}

SlcanServer::SlcanServer(std::shared_ptr<Bus> bus, std::shared_ptr<serial::Port> port,
                         SlcanServerOptions options)
    : bus_(std::move(bus)), opts_(std::move(options)), port_(std::move(port)), session_(opts_.identity) {
    if (!bus_) throw InvalidArgument("SlcanServer: no bus");
    if (!port_) throw InvalidArgument("SlcanServer: no port");
    start();
}

void SlcanServer::start() {
    check_options(opts_);
    if (auto* tty = dynamic_cast<serial::TtyPort*>(port_.get())) tty->set_write_timeout(opts_.write_timeout);
    queue_.reserve(1024);
    sub_ = bus_->subscribe(Filter{}, [this](const Frame& f) { on_bus_frame(f); });
    reader_ = std::thread([this] { reader(); });
    writer_ = std::thread([this] { writer(); });
}

SlcanServer::~SlcanServer() { close(); }

void SlcanServer::close() {
    std::call_once(close_once_, [&] {
        bus_->unsubscribe(sub_);  // after this no callback touches the queue
        {
            std::lock_guard lock(mutex_);
            stop_ = true;
        }
        cv_.notify_all();
        port_->close();  // wakes the reader and a blocked writer
        if (reader_.joinable()) reader_.join();
        if (writer_.joinable()) writer_.join();
        if (pty_) pty_->close();
        open_.store(false);
    });
}

SlcanServerStats SlcanServer::stats() const {
    std::lock_guard lock(mutex_);
    SlcanServerStats s = stats_;
    s.open = open_.load();
    return s;
}

void SlcanServer::write_bytes(const std::string& bytes) {
    std::lock_guard wl(write_mutex_);
    port_->write(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
}

void SlcanServer::reader() {
    std::array<std::uint8_t, 4096> buf;
    for (;;) {
        std::size_t n = 0;
        try {
            n = port_->read(buf, std::chrono::milliseconds(200));
        } catch (const ClosedError&) {
            return;
        } catch (const LinkDown&) {
            // The peer side vanished (an external port); wait and retry, no spin.
            std::unique_lock lock(mutex_);
            if (cv_.wait_for(lock, std::chrono::milliseconds(100), [&] { return stop_; })) return;
            continue;
        }
        {
            std::lock_guard lock(mutex_);
            if (stop_) return;
        }
        try {
            decoder_.feed(std::span(buf.data(), n), [&](const Command& c) { on_command(c); });
        } catch (const ClosedError&) {
            return;
        } catch (const Error&) {
            // A reply we could not write (peer not reading): the peer will time out.
        }
    }
}

void SlcanServer::on_command(const Command& c) {
    std::uint8_t flags = 0;
    if (c.kind == CommandKind::Status)
        flags = static_cast<std::uint8_t>(slcan::state_to_status(bus_->state()) | latched_flags_.exchange(0));
    slcan::AdapterReply r = session_.handle(c, flags);
    const bool was_open = open_.exchange(session_.is_open());
    timestamps_.store(session_.timestamps());
    if (was_open && !session_.is_open()) {
        std::lock_guard lock(mutex_);
        queue_.clear();  // nothing is forwarded once the channel is closed
    }
    bool refused = !r.bytes.empty() && r.bytes.back() == slcan::kBel;
    if (r.transmit) {
        try {
            bus_->send(*r.transmit, opts_.bus_send_timeout);
        } catch (const Error&) {
            r.bytes = slcan::AdapterSession::transmit_failed();
            refused = true;
            std::lock_guard lock(mutex_);
            ++stats_.transmit_failed;
        }
    }
    {
        std::lock_guard lock(mutex_);
        ++stats_.commands;
        if (refused) ++stats_.invalid_commands;
        if (r.transmit && !refused) ++stats_.transmitted;
    }
    write_bytes(r.bytes);
}

void SlcanServer::on_bus_frame(const Frame& f) {
    if (!open_.load(std::memory_order_relaxed) || f.is_fd()) return;
    {
        std::lock_guard lock(mutex_);
        if (stop_) return;
        if (queue_.size() >= opts_.queue_size) {
            ++stats_.forward_dropped;
            latched_flags_.fetch_or(slcan::kStatusDataOverrun | slcan::kStatusRxFifoFull);
            return;
        }
        queue_.push_back(f);
    }
    cv_.notify_one();
}

void SlcanServer::writer() {
    std::vector<Frame> batch;
    batch.reserve(1024);
    std::string out;
    for (;;) {
        {
            std::unique_lock lock(mutex_);
            cv_.wait(lock, [&] { return stop_ || !queue_.empty(); });
            if (stop_) return;
            batch.swap(queue_);
        }
        const bool ts = timestamps_.load();
        const auto ms = static_cast<std::uint16_t>(((monotonic_ns() - epoch_ns_) / 1000000) % 60000);
        out.clear();
        char line[slcan::kMtu];
        for (const Frame& f : batch) {
            const std::size_t n = slcan::encode_frame_into(f, line, ts ? std::optional<std::uint16_t>(ms) : std::nullopt);
            out.append(line, n);
        }
        bool ok = open_.load();
        if (ok) {
            try {
                write_bytes(out);
            } catch (const ClosedError&) {
                return;
            } catch (const Error&) {
                ok = false;
            }
        }
        {
            std::lock_guard lock(mutex_);
            if (ok) stats_.forwarded += batch.size();
            else stats_.forward_dropped += batch.size();
        }
        batch.clear();
    }
}

}  // namespace motorbus::can
