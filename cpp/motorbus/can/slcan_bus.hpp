// SlcanBus: a motorbus Bus over an SLCAN adapter (CANable, USBtin, CANUSB...)
// on a serial port.
//
// Open sequence: `C` (close whatever a previous session left open; a BEL for
// "already closed" is fine), `Sn` or `sxxyy`, optionally `Z1`, then `O` (or
// `L` for listen-only).  One receive thread decodes the adapter's stream and
// dispatches frames.
//
// Transmit acknowledgements: a Lawicel adapter answers every command with CR,
// `z`/`Z` or BEL, in order.  With `wait_for_acks` (the default) at most
// `tx_window` commands are unanswered at any time; send() blocks (back-pressure)
// while the window is full and throws TimeoutError at its deadline.  A BEL
// NACK completes the oldest outstanding command: for a frame it counts
// `tx_dropped` (the adapter refused it: channel closed, FIFO full) and the
// next flush_tx() raises ProtocolError naming it.  send() itself does not
// wait for its own ack (that would cost a round trip per frame).  Frames sent
// in a burst (see tx_coalesce) are written in batches by a writer thread; a
// batch lost to a dead link is counted in tx_dropped.  Adapters
// that never answer (early CANable firmware, a python-can peer on a pty) need
// `wait_for_acks = false`.
#pragma once
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/slcan_codec.hpp"
#include "motorbus/serial/port.hpp"

namespace motorbus::can {

struct SlcanOptions {
    unsigned bitrate = 500000;            // CAN bit rate -> Sn; 0 = leave the adapter's setting
    std::optional<std::uint16_t> btr;     // BTR0<<8|BTR1 -> sxxyy instead of Sn
    bool listen_only = false;             // `L` instead of `O`
    bool timestamps = false;              // `Z1`: adapter appends a 4-hex ms timestamp
    bool echo_suppression = false;        // drop received frames that echo ours (L13)
    bool wait_for_acks = true;            // see the header comment
    std::size_t tx_window = 16;           // unanswered commands before send() blocks
    Duration ack_timeout = std::chrono::seconds(1);     // an unanswered command is given up
    Duration open_timeout = std::chrono::seconds(1);    // per open-sequence command
    Duration status_poll = Duration::zero();             // `F` every period (0 = never)
    Duration partial_line_timeout = std::chrono::milliseconds(500);  // L2
    Duration echo_window = std::chrono::seconds(1);      // how long a sent frame may echo
    // A send() within this time of the previous one is a burst: it is queued
    // and written in batches by a writer thread (one write() per batch)
    // instead of one write() per frame.  An isolated frame is written at once.
    // 0 = always write directly.
    Duration tx_coalesce = std::chrono::microseconds(20);
    Duration reconnect_min = std::chrono::milliseconds(100);  // L14 backoff start
    Duration reconnect_max = std::chrono::seconds(5);         // L14 backoff cap
    unsigned tty_baud = 115200;           // serial line speed for open_slcan (0 = keep)
    BusOptions bus;
};

// Throws InvalidArgument naming the field: a bit rate with no Sn code (and no
// btr), an empty tx window, a negative duration, reconnect_min > reconnect_max.
void check_options(const SlcanOptions& options);

struct SlcanStats {
    std::uint64_t acks = 0;               // CR / z / Z answering a command
    std::uint64_t nacks = 0;              // BEL answering a command (or unsolicited)
    std::uint64_t ack_timeouts = 0;       // commands never answered within ack_timeout
    std::uint64_t echoes_suppressed = 0;  // L13
    std::uint64_t link_downs = 0;         // L14
    std::uint64_t reconnects = 0;         // successful re-opens after a link down
    std::uint64_t partial_lines_dropped = 0;  // L2
    std::uint64_t status_replies = 0;
    std::uint8_t last_status = 0;         // last `F` flags
    bool link_up = false;
    std::string version;                  // last `V` reply, e.g. "V1013"
    std::string serial_number;            // last `N` reply
};

class SlcanBus final : public Bus {
public:
    using PortFactory = std::function<std::shared_ptr<serial::Port>()>;

    // Runs the open sequence on `port`; throws TimeoutError / ProtocolError if
    // the adapter does not accept it.  With a `reconnect` factory, a lost link
    // (EOF/EIO) is re-opened with exponential backoff; without one it stays down.
    SlcanBus(std::shared_ptr<serial::Port> port, SlcanOptions options, PortFactory reconnect = {});
    ~SlcanBus() override;

    // Waits until every command sent so far is answered.  Throws TimeoutError,
    // or ProtocolError when the adapter NACKed frames since the last call.
    void flush_tx(Duration timeout);
    // Asks the adapter for `F` now and waits for the reply (wait_for_acks only).
    std::uint8_t query_status(Duration timeout);
    SlcanStats stats() const;
    bool link_up() const;

protected:
    void do_send(const Frame& frame, Deadline deadline) override;
    void do_close() override;

private:
    struct Pending {
        char cmd;                 // 't','T','F','V','N',...
        Deadline expires;
        bool is_frame;
        Frame frame{};            // for NACK reports
    };
    struct Echo {
        Frame frame;
        Deadline expires;
    };

    void run();
    void tx_writer();
    void handle(const slcan::Event& e);
    bool complete_oldest(bool ok, char reply_kind);
    void expire_pending(Deadline now);
    void link_lost(const std::string& why);
    bool reopen();
    void open_sequence(serial::Port& port);
    // Writes `line` (with CR) and reads until the adapter answers; used only
    // while no receive thread reads the port (open sequence).
    void command_inline(serial::Port& port, const std::string& line, bool bel_ok);
    void write_command(const std::string& line, char kind, Deadline deadline);
    // Waits (mutex_ held) until this thread may write one line; throws
    // ClosedError / LinkDown / TimeoutError.  release_writer() ends the claim.
    void claim_writer(std::unique_lock<std::mutex>& lock, Deadline deadline);
    void release_writer();
    struct WriterRelease {
        SlcanBus* bus;
        ~WriterRelease() { bus->release_writer(); }
    };

    SlcanOptions opts_;
    PortFactory factory_;
    slcan::StreamDecoder decoder_;  // receive thread (or the opener before it starts)

    mutable std::mutex mutex_;      // everything below
    bool writing_ = false;          // a thread owns the port for one whole line
    static constexpr std::size_t kTxBufMax = 16384;  // bytes of queued burst lines
    std::string txbuf_;             // burst lines waiting for the writer thread
    std::size_t txbuf_frames_ = 0;
    Deadline last_send_{};
    std::condition_variable cv_;
    std::shared_ptr<serial::Port> port_;
    std::deque<Pending> pending_;
    std::deque<Echo> echoes_;
    bool stop_ = false;
    bool link_up_ = false;
    std::uint64_t nacked_frames_since_flush_ = 0;
    std::string last_nacked_;
    SlcanStats stats_;

    // Inline command state (open sequence only).
    bool awaiting_ = false;
    bool awaited_ok_ = false;
    bool awaited_done_ = false;

    std::thread thread_;     // receive
    std::thread tx_thread_;  // burst writer
};

// Opens the serial device at `path` and an SlcanBus on it, with reconnect on.
std::shared_ptr<SlcanBus> open_slcan(const std::string& path, unsigned bitrate = 500000,
                                     SlcanOptions options = {});

}  // namespace motorbus::can
