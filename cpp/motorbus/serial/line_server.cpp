#include "motorbus/serial/line_server.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include "motorbus/serial/line_framer.hpp"

namespace motorbus::serial {

namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kBorrowedPoll = std::chrono::milliseconds(20);
}  // namespace

PtyLineServer::PtyLineServer(std::vector<std::shared_ptr<LineDevice>> devices, unsigned baud)
    : pty_(std::make_unique<PtyPair>()), port_(pty_->port()), owns_port_(true), baud_(baud),
      devices_(std::move(devices)) {
    // A client that stops reading must not wedge the server thread forever.
    pty_->master()->set_write_timeout(std::chrono::seconds(1));
    start();
}

PtyLineServer::PtyLineServer(std::shared_ptr<Port> port, std::vector<std::shared_ptr<LineDevice>> devices,
                             unsigned baud)
    : port_(std::move(port)), owns_port_(false), baud_(baud), devices_(std::move(devices)) {
    if (!port_) throw InvalidArgument("PtyLineServer: port is null");
    start();
}

void PtyLineServer::start() {
    for (const auto& d : devices_)
        if (!d) throw InvalidArgument("PtyLineServer: device is null");
    thread_ = std::thread([this] { run(); });
}

PtyLineServer::~PtyLineServer() { close(); }

void PtyLineServer::attach(std::shared_ptr<LineDevice> device) {
    if (!device) throw InvalidArgument("PtyLineServer::attach: device is null");
    std::lock_guard lk(devices_mutex_);
    devices_.push_back(std::move(device));
    devices_changed_ = true;
}

const std::string& PtyLineServer::slave_path() const { return pty_ ? pty_->slave_path() : no_path_; }

void PtyLineServer::close() {
    std::lock_guard lk(close_mutex_);
    stop_ = true;
    if (owns_port_ && pty_) pty_->master()->close();  // wakes the blocked read at once
    if (thread_.joinable()) thread_.join();
    if (pty_) pty_->close();
    stopped_ = true;
}

LineServerCounters PtyLineServer::counters() const {
    LineServerCounters out;
    out.bytes_in = c_.bytes_in;
    out.bytes_out = c_.bytes_out;
    out.lines = c_.lines;
    out.overlong_lines = c_.overlong_lines;
    out.replies = c_.replies;
    out.device_errors = c_.device_errors;
    out.dropped_replies = c_.dropped_replies;
    return out;
}

void PtyLineServer::write_paced(const std::string& bytes) {
    if (bytes.empty()) return;
    try {
        if (baud_ == 0) {
            port_->write({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()});
        } else {
            // Each chunk is released when a real UART would have finished sending
            // it, so a reader never sees bytes earlier than on the wire.
            const auto byte_time = std::chrono::nanoseconds(10'000'000'000LL / baud_);
            const std::size_t chunk = std::max<std::size_t>(1, baud_ / 10'000);  // ~1 ms of bytes
            auto t = Clock::now();
            for (std::size_t pos = 0; pos < bytes.size() && !stop_; pos += chunk) {
                std::size_t n = std::min(chunk, bytes.size() - pos);
                t += byte_time * static_cast<long>(n);
                std::this_thread::sleep_until(t);
                port_->write({reinterpret_cast<const std::uint8_t*>(bytes.data()) + pos, n});
            }
        }
        c_.bytes_out += bytes.size();
        ++c_.replies;
    } catch (const TimeoutError&) {
        ++c_.dropped_replies;
    }
}

void PtyLineServer::run() {
    std::optional<LineFramer> framer;
    std::vector<std::shared_ptr<LineDevice>> devices;
    std::vector<std::uint8_t> buf(4096);
    // Request bytes cannot arrive faster than the line rate either.
    Clock::time_point rx_done{};
    const auto byte_time = baud_ ? std::chrono::nanoseconds(10'000'000'000LL / baud_) : std::chrono::nanoseconds(0);

    auto refresh = [&] {
        std::lock_guard lk(devices_mutex_);
        if (!devices_changed_) return;
        devices = devices_;
        devices_changed_ = false;
        std::vector<std::string> terms;
        std::size_t max_request = 1;
        for (const auto& d : devices) {
            std::string t = d->request_terminator();
            // A device with an unusable terminator falls back to CR.
            if (t.empty() || t.size() > LineFramer::kMaxTerminator) t.assign(1, '\r');
            if (std::find(terms.begin(), terms.end(), t) == terms.end()) terms.push_back(t);
            max_request = std::max(max_request, std::min(d->max_request(), LineFramer::kMaxLineLimit));
        }
        if (terms.empty()) terms.push_back("\r");
        framer.emplace(std::move(terms), max_request);
    };

    auto call = [&](LineDevice& d, const FramedLine& line) -> std::string {
        try {
            if (line.kind == FramedLine::Kind::Overlong || line.text.size() > d.max_request())
                return d.on_overlong();
            return d.on_line(line.text);
        } catch (...) {
            ++c_.device_errors;
            return {};
        }
    };

    try {
        while (!stop_) {
            std::size_t n = port_->read(buf, owns_port_ ? std::chrono::nanoseconds(-1) : kBorrowedPoll);
            if (n == 0) continue;
            c_.bytes_in += n;
            if (baud_ && owns_port_ && enforce_baud_.load()) {
                // The pty master reports the speed the client set on its side.
                auto* tty = dynamic_cast<TtyPort*>(port_.get());
                if (tty && tty->baud() != baud_)
                    for (std::size_t i = 0; i < n; ++i) buf[i] = static_cast<std::uint8_t>((buf[i] ^ 0x55u) | 0x80u);
            }
            if (baud_) rx_done = std::max(rx_done, Clock::now()) + byte_time * static_cast<long>(n);
            refresh();
            std::span<const std::uint8_t> in(buf.data(), n);
            while (!in.empty() && !stop_) {
                std::size_t used = 0;
                auto line = framer->push(in, used);
                in = in.subspan(used);
                if (!line) break;
                if (line->kind == FramedLine::Kind::Line)
                    ++c_.lines;
                else
                    ++c_.overlong_lines;
                std::string replies;
                for (const auto& d : devices) d->line_ends();
                for (const auto& d : devices) replies += call(*d, *line);
                if (replies.empty()) continue;
                if (baud_) std::this_thread::sleep_until(rx_done);
                write_paced(replies);
            }
        }
    } catch (const ClosedError&) {
    } catch (const LinkDown&) {
    }
    stopped_ = true;
}

}  // namespace motorbus::serial
