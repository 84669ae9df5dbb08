// Frame logs: record a bus to candump (-L) or Vector ASC text, read them
// back, and replay them onto a bus with the original timing or flat out.
// Both formats are the ones python-can's LogReader reads, so logs move freely
// between motorbus, can-utils, python-can and CANalyzer-style tools.
#pragma once
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motorbus/can/bus.hpp"

namespace motorbus::can {

enum class LogFormat { Candump, Asc };
// ".asc" -> Asc, anything else (".log", ".candump") -> Candump.
LogFormat log_format_for(std::string_view path);
// "candump" (also "log", the file extension) or "asc"; nullopt if unknown.
std::optional<LogFormat> log_format_from_name(std::string_view name);

struct LogEntry {
    Frame frame;
    double time = 0.0;     // seconds: epoch time (candump) or absolute time (ASC)
    std::string channel;   // "can0", or "1" for ASC
    bool rx = true;
};

// One candump -L line: "(1700000000.123456) can0 123#DEADBEEF [R|T]".
// nullopt for anything else (bad lines are skipped by readers and counted).
std::optional<LogEntry> parse_candump_line(std::string_view line);
std::string format_candump_line(const LogEntry& e);

// Reads a whole log file.  `bad_lines` (optional) counts lines that were not frames.
std::vector<LogEntry> read_log(const std::string& path, std::size_t* bad_lines = nullptr);
// Parses an ASC file's text (header date + "Begin Triggerblock" + message lines).
std::vector<LogEntry> parse_asc(std::string_view text, std::size_t* bad_lines = nullptr);

// Subscribes to every frame the bus receives and appends it to `path`.
class Recorder {
public:
    Recorder(std::shared_ptr<Bus> bus, const std::string& path,
             std::optional<LogFormat> format = std::nullopt, std::string channel = "can0");
    ~Recorder();
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;

    // Also log a frame we sent (direction T), e.g. from a bus without receive_own.
    void log_sent(const Frame& f);
    void stop();  // unsubscribes, flushes and closes; idempotent
    std::size_t count() const;

private:
    void write(const Frame& f, bool rx);
    std::shared_ptr<Bus> bus_;
    LogFormat format_;
    std::string channel_;
    mutable std::mutex mutex_;
    std::FILE* file_ = nullptr;
    SubscriptionId sub_ = 0;
    std::size_t count_ = 0;
    double epoch_offset_;   // epoch seconds minus monotonic seconds, fixed at start
    double asc_start_ = 0;  // ASC: time of the "Begin Triggerblock" line (ms resolution)
};

// Sends `entries` onto `bus`.  speed 1.0 = original timing, 2.0 = twice as
// fast, 0 = as fast as the bus accepts.  Returns the number of frames sent.
std::size_t play(Bus& bus, const std::vector<LogEntry>& entries, double speed = 1.0,
                 Duration send_timeout = std::chrono::seconds(1));

}  // namespace motorbus::can
