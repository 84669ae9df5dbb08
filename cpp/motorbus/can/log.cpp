#include "motorbus/can/log.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "motorbus/errors.hpp"
#include "motorbus/runtime/interrupt.hpp"

namespace motorbus::can {

namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Parses exactly `s` as unsigned hex into `out`; false on any non-hex or overflow.
bool parse_hex(std::string_view s, std::uint32_t& out) {
    if (s.empty() || s.size() > 8) return false;
    std::uint32_t v = 0;
    for (char c : s) {
        int h = hex_value(c);
        if (h < 0) return false;
        v = (v << 4) | static_cast<std::uint32_t>(h);
    }
    out = v;
    return true;
}

bool parse_double(std::string_view s, double& out) {
    if (s.empty() || s.size() > 40) return false;
    std::string tmp(s);
    char* end = nullptr;
    out = std::strtod(tmp.c_str(), &end);
    return end == tmp.c_str() + tmp.size() && std::isfinite(out);
}

// A log time (seconds) this library reads: one whose "%.6f" form it can read back
// (|t| < 1e18 s writes at most 26 characters; the reader takes 40).
bool parse_log_time(std::string_view s, double& out) {
    return parse_double(s, out) && std::fabs(out) < 1e18;
}

std::vector<std::string_view> split_ws(std::string_view line) {
    std::vector<std::string_view> parts;
    std::size_t i = 0;
    while (i < line.size() && parts.size() < 64) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        std::size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
        if (j > i) parts.push_back(line.substr(i, j - i));
        i = j;
    }
    return parts;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ')) s.remove_suffix(1);
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    return s;
}

double epoch_minus_monotonic() {
    const double wall = std::chrono::duration<double>(
                            std::chrono::system_clock::now().time_since_epoch()).count();
    return wall - monotonic_ns() / 1e9;
}

// "Sat Nov 21 14:01:02.123 2026" in local time, as Vector tools and python-can's ASCWriter write.
std::string asc_date(double epoch) {
    std::time_t secs = static_cast<std::time_t>(std::floor(epoch));
    int ms = static_cast<int>(std::lround((epoch - std::floor(epoch)) * 1000.0));
    if (ms == 1000) { ms = 999; }
    std::tm tm{};
    localtime_r(&secs, &tm);
    char buf[64];
    std::strftime(buf, sizeof buf, "%a %b %d %H:%M:%S", &tm);
    char year[16];
    std::strftime(year, sizeof year, "%Y", &tm);
    char out[96];
    std::snprintf(out, sizeof out, "%s.%03d %s", buf, ms, year);
    return out;
}

// Parses the ASC date as python-can does (month names, 24 h or 12 h clock).
std::optional<double> parse_asc_date(std::string_view s) {
    static const char* months[] = {"Jan", "Feb", "Mar", "Apr", "May", "Jun",
                                   "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"};
    auto p = split_ws(s);
    // [weekday] month day HH:MM:SS[.mmm] [AM|PM] year
    if (p.size() < 4) return std::nullopt;
    std::size_t i = (p.size() >= 5 && p[0].size() == 3 && hex_value(p[0][0]) < 0 &&
                     std::isalpha(static_cast<unsigned char>(p[1][0])))
                        ? 1
                        : 0;
    std::tm tm{};
    int mon = -1;
    for (int k = 0; k < 12; ++k)
        if (p[i] == months[k]) mon = k;
    if (mon < 0) return std::nullopt;
    tm.tm_mon = mon;
    tm.tm_mday = std::atoi(std::string(p[i + 1]).c_str());
    int hh = 0, mm = 0;
    double ss = 0;
    std::string hms(p[i + 2]);
    if (std::sscanf(hms.c_str(), "%d:%d:%lf", &hh, &mm, &ss) != 3) return std::nullopt;
    std::size_t yi = i + 3;
    if (yi < p.size() && (p[yi] == "PM" || p[yi] == "AM")) {
        if (p[yi] == "PM" && hh < 12) hh += 12;
        if (p[yi] == "AM" && hh == 12) hh = 0;
        ++yi;
    }
    if (yi >= p.size()) return std::nullopt;
    tm.tm_year = std::atoi(std::string(p[yi]).c_str()) - 1900;
    tm.tm_hour = hh;
    tm.tm_min = mm;
    tm.tm_sec = 0;
    tm.tm_isdst = -1;
    std::time_t t = std::mktime(&tm);
    if (t == static_cast<std::time_t>(-1)) return std::nullopt;
    return static_cast<double>(t) + ss;
}

}  // namespace

std::optional<LogFormat> log_format_from_name(std::string_view name) {
    if (name == "candump" || name == "log") return LogFormat::Candump;
    if (name == "asc") return LogFormat::Asc;
    return std::nullopt;
}

LogFormat log_format_for(std::string_view path) {
    auto dot = path.rfind('.');
    if (dot != std::string_view::npos) {
        std::string ext(path.substr(dot + 1));
        for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (ext == "asc") return LogFormat::Asc;
    }
    return LogFormat::Candump;
}

std::optional<LogEntry> parse_candump_line(std::string_view line) {
    auto p = split_ws(trim(line));
    if (p.size() != 3 && p.size() != 4) return std::nullopt;
    LogEntry e;
    if (p[0].size() < 3 || p[0].front() != '(' || p[0].back() != ')') return std::nullopt;
    if (!parse_log_time(p[0].substr(1, p[0].size() - 2), e.time)) return std::nullopt;
    // An interface name is printable text: a control byte (NUL, ESC...) inside it
    // would not survive being written back (found by fuzz_can_log at 3.4 M runs).
    for (char c : p[1])
        if (static_cast<unsigned char>(c) < 0x21 || static_cast<unsigned char>(c) == 0x7F) return std::nullopt;
    e.channel = std::string(p[1]);
    if (p.size() == 4) {
        if (p[3] == "R" || p[3] == "r") e.rx = true;
        else if (p[3] == "T" || p[3] == "t") e.rx = false;
        else return std::nullopt;
    }
    auto frame = p[2];
    auto hash = frame.find('#');
    if (hash == std::string_view::npos) return std::nullopt;
    auto id_s = frame.substr(0, hash);
    auto data_s = frame.substr(hash + 1);
    std::uint32_t id;
    if ((id_s.size() != 3 && id_s.size() != 8) || !parse_hex(id_s, id)) return std::nullopt;
    const bool extended = id_s.size() == 8;
    if (!data_s.empty() && data_s[0] == '#') return std::nullopt;  // CAN FD: not yet
    Frame f;
    f.id = id;
    f.extended = extended;
    if (!data_s.empty() && (data_s[0] == 'R' || data_s[0] == 'r')) {
        f.rtr = true;
        if (data_s.size() == 2 && data_s[1] >= '0' && data_s[1] <= '8')
            f.len = static_cast<std::uint8_t>(data_s[1] - '0');
        else if (data_s.size() != 1)
            return std::nullopt;
    } else {
        if (data_s.size() % 2 || data_s.size() > 16) return std::nullopt;
        for (std::size_t i = 0; i < data_s.size(); i += 2) {
            int hi = hex_value(data_s[i]), lo = hex_value(data_s[i + 1]);
            if (hi < 0 || lo < 0) return std::nullopt;
            f.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
        }
        f.len = static_cast<std::uint8_t>(data_s.size() / 2);
    }
    if (!f.valid()) return std::nullopt;
    f.timestamp_ns = 0;
    e.frame = f;
    return e;
}

std::string format_candump_line(const LogEntry& e) {
    // No fixed-size buffer: a long interface name or a huge time must be written whole
    // (a 64-byte buffer cut both, and the line then read back as another frame —
    // found by fuzz_can_log at 4.3 M runs).
    char time[32];
    const int n = std::snprintf(time, sizeof time, "(%.6f) ", e.time);
    std::string s;
    if (n >= 0 && static_cast<std::size_t>(n) < sizeof time) {
        s = time;
    } else {
        s.resize(static_cast<std::size_t>(std::max(n, 0)) + 1);
        std::snprintf(s.data(), s.size(), "(%.6f) ", e.time);
        s.pop_back();  // the NUL snprintf wrote
    }
    s += e.channel;
    s += ' ';
    s += e.frame.to_string();
    if (e.frame.rtr && e.frame.len == 0) s.pop_back();  // "123#R" not "123#R0"
    s += e.rx ? " R" : " T";
    return s;
}

std::vector<LogEntry> parse_asc(std::string_view text, std::size_t* bad_lines) {
    std::vector<LogEntry> out;
    double start = 0;
    bool hex = true;
    std::size_t pos = 0;
    while (pos < text.size()) {
        auto nl = text.find('\n', pos);
        auto line = trim(text.substr(pos, nl == std::string_view::npos ? text.size() - pos : nl - pos));
        pos = nl == std::string_view::npos ? text.size() : nl + 1;
        if (line.empty()) continue;
        auto p = split_ws(line);
        if (p.empty()) continue;
        if (p[0] == "date" || p[0] == "internal" || p[0] == "End" || p[0] == "//") continue;
        if (p[0] == "base") {
            hex = p.size() < 2 || p[1] != "dec";
            continue;
        }
        if (p[0] == "Begin" && p.size() >= 4) {
            std::string rest;
            for (std::size_t i = 3; i < p.size(); ++i) rest += std::string(p[i]) + " ";
            if (auto t = parse_asc_date(rest)) start = *t;
            continue;
        }
        // "<time> <channel> <id>[x] <Rx|Tx> d <dlc> <bytes...>" or "... r [dlc]"
        double t;
        if (p.size() >= 2 && p[1] == "Start") continue;  // "<t> Start of measurement"
        if (p.size() < 4 || !parse_double(p[0], t)) {
            if (bad_lines) ++*bad_lines;
            continue;
        }
        bool is_digit_channel = !p[1].empty();
        for (char c : p[1]) is_digit_channel &= (c >= '0' && c <= '9');
        if (!is_digit_channel || p.size() < 5) {
            if (bad_lines) ++*bad_lines;
            continue;
        }
        LogEntry e;
        e.time = start + t;
        e.channel = std::string(p[1]);
        auto id_s = p[2];
        Frame f;
        if (!id_s.empty() && (id_s.back() == 'x' || id_s.back() == 'X')) {
            f.extended = true;
            id_s.remove_suffix(1);
        }
        std::uint32_t id = 0;
        bool ok = hex ? parse_hex(id_s, id) : false;
        if (!hex) {
            ok = !id_s.empty() && id_s.size() <= 10;
            for (char c : id_s) ok &= (c >= '0' && c <= '9');
            if (ok) {
                unsigned long long v = std::stoull(std::string(id_s));
                ok = v <= 0x1FFFFFFF;
                id = static_cast<std::uint32_t>(v);
            }
        }
        if (!ok || (p[3] != "Rx" && p[3] != "Tx")) {
            if (bad_lines) ++*bad_lines;
            continue;
        }
        f.id = id;
        e.rx = p[3] == "Rx";
        const int base = hex ? 16 : 10;
        if (p[4] == "r" || p[4] == "R") {
            f.rtr = true;
            if (p.size() > 5 && p[5].size() == 1 && p[5][0] >= '0' && p[5][0] <= '8')
                f.len = static_cast<std::uint8_t>(p[5][0] - '0');
        } else if (p[4] == "d" && p.size() >= 6) {
            std::uint32_t dlc;
            if (!parse_hex(p[5], dlc) || dlc > 8 || p.size() < 6 + dlc) {
                if (bad_lines) ++*bad_lines;
                continue;
            }
            f.len = static_cast<std::uint8_t>(dlc);
            bool good = true;
            for (std::uint32_t i = 0; i < dlc; ++i) {
                std::uint32_t v = 0;
                if (base == 16) good &= parse_hex(p[6 + i], v) && v <= 0xFF;
                else {
                    std::string b(p[6 + i]);
                    char* end = nullptr;
                    v = static_cast<std::uint32_t>(std::strtoul(b.c_str(), &end, 10));
                    good &= end && *end == 0 && v <= 0xFF;
                }
                f.data[i] = static_cast<std::uint8_t>(v);
            }
            if (!good) {
                if (bad_lines) ++*bad_lines;
                continue;
            }
        } else {
            if (bad_lines) ++*bad_lines;
            continue;
        }
        if (!f.valid()) {
            if (bad_lines) ++*bad_lines;
            continue;
        }
        e.frame = f;
        out.push_back(e);
    }
    return out;
}

std::vector<LogEntry> read_log(const std::string& path, std::size_t* bad_lines) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InvalidArgument("log file: cannot open '" + path + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    if (log_format_for(path) == LogFormat::Asc) return parse_asc(text, bad_lines);
    std::vector<LogEntry> out;
    std::size_t pos = 0;
    while (pos < text.size()) {
        auto nl = text.find('\n', pos);
        std::string_view line(text.data() + pos, (nl == std::string::npos ? text.size() : nl) - pos);
        pos = nl == std::string::npos ? text.size() : nl + 1;
        if (trim(line).empty()) continue;
        if (auto e = parse_candump_line(line)) out.push_back(std::move(*e));
        else if (bad_lines) ++*bad_lines;
    }
    return out;
}

Recorder::Recorder(std::shared_ptr<Bus> bus, const std::string& path,
                   std::optional<LogFormat> format, std::string channel)
    : bus_(std::move(bus)),
      format_(format.value_or(log_format_for(path))),
      channel_(std::move(channel)),
      epoch_offset_(epoch_minus_monotonic()) {
    file_ = std::fopen(path.c_str(), "w");
    if (!file_) throw InvalidArgument("log file: cannot create '" + path + "': " + std::strerror(errno));
    if (format_ == LogFormat::Asc) {
        // The trigger block date has millisecond resolution; message times are
        // written relative to that rounded instant so readers recover the
        // absolute time to the microsecond.
        const double now = monotonic_ns() / 1e9 + epoch_offset_;
        asc_start_ = std::floor(now * 1000.0) / 1000.0;
        const std::string d = asc_date(asc_start_);
        std::fprintf(file_, "date %s\nbase hex  timestamps absolute\ninternal events logged\n", d.c_str());
        std::fprintf(file_, "// version 9.0.0\nBegin Triggerblock %s\n", d.c_str());
        std::fprintf(file_, "%9.6f Start of measurement\n", 0.0);
    }
    sub_ = bus_->subscribe(Filter{}, [this](const Frame& f) {
        write(f, !(f.flags & kFlagLoopback));
    });
}

Recorder::~Recorder() { stop(); }

void Recorder::log_sent(const Frame& f) {
    Frame c = f;
    if (c.timestamp_ns == 0) c.timestamp_ns = monotonic_ns();
    write(c, false);
}

void Recorder::write(const Frame& f, bool rx) {
    std::lock_guard lock(mutex_);
    if (!file_) return;
    const Nanos ts = f.timestamp_ns ? f.timestamp_ns : monotonic_ns();
    const double t = ts / 1e9 + epoch_offset_;
    if (format_ == LogFormat::Candump) {
        LogEntry e{f, t, channel_, rx};
        std::string s = format_candump_line(e);
        s += '\n';
        std::fwrite(s.data(), 1, s.size(), file_);
    } else {
        char id[16];
        std::snprintf(id, sizeof id, f.extended ? "%Xx" : "%X", f.id);
        std::string line;
        char head[64];
        std::snprintf(head, sizeof head, "%9.6f 1  %-15s %-4s ", t - asc_start_, id, rx ? "Rx" : "Tx");
        line = head;
        if (f.rtr) {
            char b[8];
            std::snprintf(b, sizeof b, "r %X", f.len);
            line += b;
        } else {
            char b[8];
            std::snprintf(b, sizeof b, "d %X", f.len);
            line += b;
            for (unsigned i = 0; i < f.len; ++i) {
                std::snprintf(b, sizeof b, " %02X", f.data[i]);
                line += b;
            }
        }
        line += '\n';
        std::fwrite(line.data(), 1, line.size(), file_);
    }
    ++count_;
}

void Recorder::stop() {
    if (sub_) {
        bus_->unsubscribe(sub_);
        sub_ = 0;
    }
    std::lock_guard lock(mutex_);
    if (file_) {
        if (format_ == LogFormat::Asc) std::fputs("End TriggerBlock\n", file_);
        std::fclose(file_);
        file_ = nullptr;
    }
}

std::size_t Recorder::count() const {
    std::lock_guard lock(mutex_);
    return count_;
}

std::size_t play(Bus& bus, const std::vector<LogEntry>& entries, double speed, Duration send_timeout) {
    if (speed < 0 || std::isnan(speed)) throw InvalidArgument("play speed: must be >= 0 (0 = as fast as possible)");
    std::size_t n = 0;
    if (entries.empty()) return 0;
    const auto t0 = std::chrono::steady_clock::now();
    const double first = entries.front().time;
    for (const auto& e : entries) {
        if (speed > 0) {
            // Absolute schedule from the first frame: no drift accumulates.
            // Clamped to a year: a log's timestamps are data (a corrupt one must not
            // overflow the conversion), and a gap that long is never meant literally.
            const double offset = std::clamp((e.time - first) / speed, 0.0, 365.0 * 86400.0);
            const auto due = t0 + std::chrono::nanoseconds(static_cast<std::int64_t>(offset * 1e9));
            interruptible_sleep_for(due - std::chrono::steady_clock::now());  // Ctrl-C from Python
        }
        if (bus.closed()) break;
        Frame f = e.frame;
        f.timestamp_ns = 0;
        bus.send(f, send_timeout);
        ++n;
    }
    return n;
}

}  // namespace motorbus::can
