#include "motorbus/can/socketcand_codec.hpp"
#include "motorbus/errors.hpp"

#include <algorithm>
#include <array>
#include <cstring>

namespace motorbus::can::socketcand {

namespace {

constexpr std::size_t kMaxTokens = 72;  // fdsend: word id flags len + 64 bytes, with room

// Token positions inside one element.  Deliberately left uninitialised (trivial
// members): zeroing 72 string_views per element cost more than parsing a frame.
struct Tokens {
    struct Span {
        std::uint16_t off, len;
    };
    std::string_view src;
    Span spans[kMaxTokens];
    std::string_view operator[](int i) const { return src.substr(spans[i].off, spans[i].len); }
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Splits the inside of `< ... >` on blanks.  Returns the count, or -1 when there are too many.
int tokenize(std::string_view inner, Tokens& t) {
    t.src = inner;
    int n = 0;
    std::size_t i = 0;
    while (i < inner.size()) {
        while (i < inner.size() && is_blank(inner[i])) ++i;
        if (i >= inner.size()) break;
        std::size_t start = i;
        while (i < inner.size() && !is_blank(inner[i])) ++i;
        if (n == static_cast<int>(kMaxTokens)) return -1;
        t.spans[n++] = {static_cast<std::uint16_t>(start), static_cast<std::uint16_t>(i - start)};
    }
    return n;
}

// Id width follows the digit count, as socketcand writes them (%03X / %08X):
// up to 3 digits is an 11-bit id, 4 to 8 digits a 29-bit id.  (K7)
const char* parse_id(std::string_view tok, Frame& f) {
    if (tok.empty() || tok.size() > 8) return "id: needs 1-8 hex digits";
    std::uint32_t v = 0;
    for (char c : tok) {
        int d = hex_digit(c);
        if (d < 0) return "id: not hex";
        v = (v << 4) | static_cast<std::uint32_t>(d);
    }
    f.extended = tok.size() > 3;
    if (f.extended ? v > kMaxExtendedId : v > kMaxStandardId)
        return f.extended ? "id: above 1FFFFFFF" : "id: above 7FF";
    f.id = v;
    return nullptr;
}

// SEC[.FRACTION]: unsigned decimal seconds, 1-9 fraction digits.  (K5)
const char* parse_time(std::string_view tok, Nanos& ns) {
    std::size_t dot = tok.find('.');
    std::string_view sec = tok.substr(0, dot);
    std::string_view frac = dot == std::string_view::npos ? std::string_view{} : tok.substr(dot + 1);
    if (sec.empty() || sec.size() > 10) return "timestamp: bad seconds";
    if (dot != std::string_view::npos && (frac.empty() || frac.size() > 9))
        return "timestamp: bad fraction";
    std::int64_t s = 0, f = 0;
    for (char c : sec) {
        if (c < '0' || c > '9') return "timestamp: not decimal";
        s = s * 10 + (c - '0');
    }
    if (s > 9'000'000'000LL) return "timestamp: out of range";
    for (std::size_t i = 0; i < 9; ++i) {
        char c = i < frac.size() ? frac[i] : '0';
        if (c < '0' || c > '9') return "timestamp: not decimal";
        f = f * 10 + (c - '0');
    }
    ns = s * 1'000'000'000LL + f;
    return nullptr;
}

// Data as received in frame elements: contiguous hex ("112233") or space-separated
// bytes ("11 22 33"); every token must hold whole bytes.  (K5 odd hex, K6 too long)
const char* parse_hex_data(const Tokens& t, int first, int n, std::size_t max_len, Frame& f) {
    std::size_t len = 0;
    for (int k = first; k < n; ++k) {
        std::string_view tok = t[k];
        if (tok.size() % 2) return "data: odd number of hex digits";
        if (len + tok.size() / 2 > max_len) return "data: too many bytes";
        for (std::size_t i = 0; i < tok.size(); i += 2) {
            int hi = hex_digit(tok[i]), lo = hex_digit(tok[i + 1]);
            if (hi < 0 || lo < 0) return "data: not hex";
            f.data[len++] = static_cast<std::uint8_t>(hi << 4 | lo);
        }
    }
    f.len = static_cast<std::uint8_t>(len);
    return nullptr;
}

// One byte per token, 1-2 hex digits, as clients write them in send commands
// (python-can writes "{x:x}", so 0x0A arrives as "a").
const char* parse_byte_items(const Tokens& t, int first, int n, Frame& f) {
    for (int k = first; k < n; ++k) {
        std::string_view tok = t[k];
        if (tok.empty() || tok.size() > 2) return "data: each byte needs 1-2 hex digits";
        int v = 0;
        for (char c : tok) {
            int d = hex_digit(c);
            if (d < 0) return "data: not hex";
            v = v << 4 | d;
        }
        f.data[k - first] = static_cast<std::uint8_t>(v);
    }
    return nullptr;
}

// Decimal length (socketcand reads it with %hhu).  Hex A-F would mean > 9 anyway.
const char* parse_len(std::string_view tok, unsigned max, unsigned& len) {
    if (tok.empty() || tok.size() > 2) return "dlc: bad length";
    unsigned v = 0;
    for (char c : tok) {
        if (c < '0' || c > '9') return "dlc: not decimal";
        v = v * 10 + static_cast<unsigned>(c - '0');
    }
    if (v > max) return max == 8 ? "dlc: above 8" : "len: above 64";
    len = v;
    return nullptr;
}

const char* parse_fd_flags(std::string_view tok, Frame& f) {
    if (tok.empty() || tok.size() > 2) return "fd flags: bad";
    int v = 0;
    for (char c : tok) {
        int d = hex_digit(c);
        if (d < 0) return "fd flags: not hex";
        v = v << 4 | d;
    }
    f.flags = kFlagFd;
    if (v & 0x01) f.flags |= kFlagBrs;  // CANFD_BRS
    if (v & 0x02) f.flags |= kFlagEsi;  // CANFD_ESI
    return nullptr;
}

struct Word {
    std::string_view name;
    ElementKind kind;
};
constexpr Word kBareWords[] = {
    {"hi", ElementKind::Hi},           {"ok", ElementKind::Ok},
    {"echo", ElementKind::Echo},       {"rawmode", ElementKind::RawMode},
    {"bcmmode", ElementKind::BcmMode}, {"controlmode", ElementKind::ControlMode},
    {"isotpmode", ElementKind::IsotpMode},
};

// Builds one element in a stack buffer and appends it to the output once: the
// server encodes every frame for every client, so this is a hot path.
// The longest element we write is an fdframe with 64 bytes (~170 chars).
class Writer {
public:
    void text(std::string_view t) {
        std::memcpy(p_, t.data(), t.size());
        p_ += t.size();
    }
    void ch(char c) { *p_++ = c; }
    void hex(std::uint32_t v, int digits) {
        for (int i = digits - 1; i >= 0; --i) {
            p_[i] = kHex[v & 0xF];
            v >>= 4;
        }
        p_ += digits;
    }
    void byte(std::uint8_t b) {
        p_[0] = kHex[b >> 4];
        p_[1] = kHex[b & 0xF];
        p_ += 2;
    }
    void uint(std::uint64_t v) {
        char tmp[20];
        int n = 0;
        do {
            tmp[n++] = static_cast<char>('0' + v % 10);
            v /= 10;
        } while (v);
        while (n) *p_++ = tmp[--n];
    }
    void id(const Frame& f) {
        if (f.extended)
            hex(f.id & kMaxExtendedId, 8);
        else
            hex(f.id & kMaxStandardId, 3);
    }
    void time(Nanos ns) {  // SEC.USEC, six fraction digits like socketcand
        if (ns < 0) ns = 0;
        uint(static_cast<std::uint64_t>(ns / 1'000'000'000));
        ch('.');
        auto usec = static_cast<std::uint32_t>((ns % 1'000'000'000) / 1000);
        for (int i = 5; i >= 0; --i) {
            p_[i] = static_cast<char>('0' + usec % 10);
            usec /= 10;
        }
        p_ += 6;
    }
    void flush_to(std::string& out) { out.append(buf_, static_cast<std::size_t>(p_ - buf_)); }

private:
    static constexpr char kHex[] = "0123456789ABCDEF";
    char buf_[256];
    char* p_ = buf_;
};

std::uint8_t fd_flags_byte(const Frame& f) {
    return static_cast<std::uint8_t>(((f.flags & kFlagBrs) ? 1 : 0) | ((f.flags & kFlagEsi) ? 2 : 0));
}

// Fast paths for the two elements a busy link carries, in the exact shape
// socketcand, python-can and our encoders write them (single blanks):
//   < frame ID SEC.FRACTION HEXDATA >   (server -> client)
//   < send ID DLC B0 B1 .. >            (client -> server)
// They accept only input the general parser accepts with the same result, and
// return false for anything else, which the general parser then handles (and
// explains, when it is malformed).  Tokenizing into 72 spans first cost about
// as much as everything else on the receive path.
struct Cursor {
    const char* p;
    const char* end;
    bool take(char c) {
        if (p == end || *p != c) return false;
        ++p;
        return true;
    }
    // 1..max_digits hex digits; false if none, too many or the value is not followed by a blank.
    bool hex(int max_digits, std::uint32_t& v, int& digits) {
        v = 0;
        digits = 0;
        while (p != end) {
            int d = hex_digit(*p);
            if (d < 0) break;
            if (++digits > max_digits) return false;
            v = (v << 4) | static_cast<std::uint32_t>(d);
            ++p;
        }
        return digits > 0;
    }
};

bool fast_id(Cursor& c, Frame& f) {
    std::uint32_t v;
    int digits;
    if (!c.hex(8, v, digits)) return false;
    f.extended = digits > 3;
    if (f.extended ? v > kMaxExtendedId : v > kMaxStandardId) return false;
    f.id = v;
    return true;
}

bool fast_frame(std::string_view element, Element& out) {
    Cursor c{element.data() + 8, element.data() + element.size()};  // after "< frame "
    Frame& f = out.frame;
    if (!fast_id(c, f) || !c.take(' ')) return false;
    // SEC.FRACTION: 1-10 decimal digits, '.', 1-9 decimal digits (parse_time's rules).
    std::int64_t sec = 0, frac = 0;
    int sd = 0, fd = 0;
    while (c.p != c.end && *c.p >= '0' && *c.p <= '9') {
        if (++sd > 10) return false;
        sec = sec * 10 + (*c.p++ - '0');
    }
    if (sd == 0 || sec > 9'000'000'000LL || !c.take('.')) return false;
    while (c.p != c.end && *c.p >= '0' && *c.p <= '9') {
        if (++fd > 9) return false;
        frac = frac * 10 + (*c.p++ - '0');
    }
    if (fd == 0 || !c.take(' ')) return false;
    for (int k = fd; k < 9; ++k) frac *= 10;
    std::size_t len = 0;
    while (c.end - c.p >= 2) {
        int hi = hex_digit(c.p[0]);
        if (hi < 0) break;
        int lo = hex_digit(c.p[1]);
        if (lo < 0 || len == kMaxClassicLen) return false;
        f.data[len++] = static_cast<std::uint8_t>(hi << 4 | lo);
        c.p += 2;
    }
    if (c.end - c.p != 2 || c.p[0] != ' ' || c.p[1] != '>') return false;
    f.len = static_cast<std::uint8_t>(len);
    out.kind = ElementKind::Frame;
    out.remote_time_ns = sec * 1'000'000'000LL + frac;
    return true;
}

bool fast_send(std::string_view element, Element& out) {
    Cursor c{element.data() + 7, element.data() + element.size()};  // after "< send "
    Frame& f = out.frame;
    if (!fast_id(c, f) || !c.take(' ')) return false;
    if (c.p == c.end || *c.p < '0' || *c.p > '8') return false;
    const unsigned len = static_cast<unsigned>(*c.p++ - '0');
    for (unsigned i = 0; i < len; ++i) {
        std::uint32_t v;
        int digits;
        if (!c.take(' ') || !c.hex(2, v, digits)) return false;
        f.data[i] = static_cast<std::uint8_t>(v);
    }
    if (c.end - c.p != 2 || c.p[0] != ' ' || c.p[1] != '>') return false;
    f.len = static_cast<std::uint8_t>(len);
    out.kind = ElementKind::Send;
    return true;
}

}  // namespace

const char* to_string(ElementKind k) {
    switch (k) {
        case ElementKind::Hi: return "hi";
        case ElementKind::Ok: return "ok";
        case ElementKind::Frame: return "frame";
        case ElementKind::FdFrame: return "fdframe";
        case ElementKind::Rtr: return "rtr";
        case ElementKind::ErrorFrame: return "error";
        case ElementKind::ErrorText: return "error";
        case ElementKind::Open: return "open";
        case ElementKind::RawMode: return "rawmode";
        case ElementKind::BcmMode: return "bcmmode";
        case ElementKind::ControlMode: return "controlmode";
        case ElementKind::IsotpMode: return "isotpmode";
        case ElementKind::Send: return "send";
        case ElementKind::SendRtr: return "sendrtr";
        case ElementKind::FdSend: return "fdsend";
        case ElementKind::Echo: return "echo";
        case ElementKind::Unknown: return "unknown";
    }
    return "unknown";
}

const char* parse_element(std::string_view element, Element& out) {
    if (element.size() < 2 || element.front() != '<' || element.back() != '>')
        return "element: not enclosed in < >";
    if (element.size() > 65535) return "element: too long";
    if (element.starts_with("< frame ") || element.starts_with("< send ")) {
        out.frame = Frame{};
        out.remote_time_ns = 0;
        out.text.clear();
        if (element[2] == 'f' ? fast_frame(element, out) : fast_send(element, out)) return nullptr;
    }
    Tokens t;
    int n = tokenize(element.substr(1, element.size() - 2), t);
    if (n < 0) return "element: too many items";
    if (n == 0) return "element: empty";
    out.frame = Frame{};
    out.remote_time_ns = 0;
    out.text.clear();
    const std::string_view word = t[0];
    Frame& f = out.frame;
    const char* why = nullptr;

    if (word == "frame") {  // < frame ID SEC.USEC [DATA]* >
        out.kind = ElementKind::Frame;
        if (n < 3) return "frame: needs id and timestamp";
        if ((why = parse_id(t[1], f)) || (why = parse_time(t[2], out.remote_time_ns)) ||
            (why = parse_hex_data(t, 3, n, kMaxClassicLen, f)))
            return why;
        return nullptr;
    }
    if (word == "fdframe") {  // < fdframe ID FLAGS SEC.USEC [DATA]* >
        out.kind = ElementKind::FdFrame;
        if (n < 4) return "fdframe: needs id, flags and timestamp";
        if ((why = parse_id(t[1], f)) || (why = parse_fd_flags(t[2], f)) ||
            (why = parse_time(t[3], out.remote_time_ns)) ||
            (why = parse_hex_data(t, 4, n, kMaxFdLen, f)))
            return why;
        if (f.problem()) return "fdframe: length is not a CAN FD length";
        return nullptr;
    }
    if (word == "rtr") {  // < rtr ID SEC.USEC DLC >
        out.kind = ElementKind::Rtr;
        if (n != 4) return "rtr: needs id, timestamp and dlc";
        unsigned len = 0;
        if ((why = parse_id(t[1], f)) || (why = parse_time(t[2], out.remote_time_ns)) ||
            (why = parse_len(t[3], 8, len)))
            return why;
        f.rtr = true;
        f.len = static_cast<std::uint8_t>(len);
        return nullptr;
    }
    if (word == "error") {
        // `< error CLASS SEC.USEC >` is a bus error frame; anything else is a message.
        if (n == 3) {
            Nanos ts = 0;
            std::string_view cls = t[1];
            if (!cls.empty() && cls.size() <= 8 && !parse_time(t[2], ts)) {
                std::uint32_t v = 0;
                bool hex = true;
                for (char c : cls) {
                    int d = hex_digit(c);
                    hex &= d >= 0;
                    v = (v << 4) | static_cast<std::uint32_t>(d < 0 ? 0 : d);
                }
                if (hex && v <= kMaxExtendedId) {
                    out.kind = ElementKind::ErrorFrame;
                    f.id = v;
                    f.extended = true;
                    f.flags = kFlagError;
                    out.remote_time_ns = ts;
                    return nullptr;
                }
            }
        }
        out.kind = ElementKind::ErrorText;
        std::string_view inner = element.substr(1, element.size() - 2);
        std::size_t start = inner.find("error") + 5;
        std::string_view msg = inner.substr(start);
        while (!msg.empty() && is_blank(msg.front())) msg.remove_prefix(1);
        while (!msg.empty() && is_blank(msg.back())) msg.remove_suffix(1);
        out.text.assign(msg);
        return nullptr;
    }
    if (word == "open") {  // < open CHANNEL >
        out.kind = ElementKind::Open;
        if (n != 2) return "open: needs exactly one channel name";
        if (t[1].size() > kMaxChannelName) return "open: channel name longer than 16";
        out.text.assign(t[1]);
        return nullptr;
    }
    if (word == "send") {  // < send ID DLC [B]* >  (K10)
        out.kind = ElementKind::Send;
        if (n < 3) return "send: needs id and dlc";
        unsigned len = 0;
        if ((why = parse_id(t[1], f)) || (why = parse_len(t[2], 8, len))) return why;
        if (static_cast<unsigned>(n - 3) != len) return "send: byte count differs from dlc";
        if ((why = parse_byte_items(t, 3, n, f))) return why;
        f.len = static_cast<std::uint8_t>(len);
        return nullptr;
    }
    if (word == "sendrtr") {  // < sendrtr ID DLC >
        out.kind = ElementKind::SendRtr;
        if (n != 3) return "sendrtr: needs id and dlc";
        unsigned len = 0;
        if ((why = parse_id(t[1], f)) || (why = parse_len(t[2], 8, len))) return why;
        f.rtr = true;
        f.len = static_cast<std::uint8_t>(len);
        return nullptr;
    }
    if (word == "fdsend") {  // < fdsend ID FLAGS LEN [B]* >
        out.kind = ElementKind::FdSend;
        if (n < 4) return "fdsend: needs id, flags and len";
        unsigned len = 0;
        if ((why = parse_id(t[1], f)) || (why = parse_fd_flags(t[2], f)) ||
            (why = parse_len(t[3], 64, len)))
            return why;
        if (static_cast<unsigned>(n - 4) != len) return "fdsend: byte count differs from len";
        if ((why = parse_byte_items(t, 4, n, f))) return why;
        f.len = static_cast<std::uint8_t>(len);
        if (f.problem()) return "fdsend: len is not a CAN FD length";
        return nullptr;
    }
    for (const Word& w : kBareWords) {
        if (word == w.name) {
            if (n != 1) return "element: command takes no arguments";
            out.kind = w.kind;
            return nullptr;
        }
    }
    out.kind = ElementKind::Unknown;
    out.text.assign(word.substr(0, 32));
    return nullptr;
}

void check_channel_name(const std::string& channel, const char* field) {
    if (channel.empty() || channel.size() > socketcand::kMaxChannelName)
        throw InvalidArgument(std::string(field) + ": '" + channel + "' must be 1-16 characters");
    for (char c : channel)
        if (c == '<' || c == '>' || c == ' ' || static_cast<unsigned char>(c) < 0x21 ||
            static_cast<unsigned char>(c) == 0x7F)
            throw InvalidArgument(std::string(field) + ": '" + channel + "' contains a blank, a control character or < >");
}

void check_max_element(std::size_t max_element) {
    if (max_element < kMinMaxElement || max_element > kMaxMaxElement)
        throw InvalidArgument("max_element: " + std::to_string(max_element) + ", must be " +
                              std::to_string(kMinMaxElement) + "-" + std::to_string(kMaxMaxElement) +
                              " bytes (a frame element must fit)");
}

ElementParser::ElementParser(std::size_t max_element)
    : max_element_(std::clamp<std::size_t>(max_element, 8, 65535)) {
    buffer_.reserve(max_element_);
}

void ElementParser::reset() {
    buffer_.clear();
    in_element_ = false;
    skipping_ = false;
    ready_ = false;
}

ElementParser::Next ElementParser::find_element(std::span<const char> bytes, std::size_t from) {
    const char* p = bytes.data();
    const std::size_t n = bytes.size();
    std::size_t i = from;
    while (i < n && p[i] != '<') {
        if (!skipping_ && !is_blank(p[i])) ++stats_.discarded_bytes;
        ++i;
    }
    if (i == n) return {n, false, {}};
    skipping_ = false;
    const std::size_t start = i;
    const std::size_t limit = std::min(n, start + max_element_);
    // The first '>' or '<' after start, before limit (two memchr beat a byte loop).
    std::size_t j = limit;
    if (start + 1 < limit) {
        const char* from_p = p + start + 1;
        const void* gt = std::memchr(from_p, '>', limit - start - 1);
        const char* stop = gt ? static_cast<const char*>(gt) : p + limit;
        const void* lt = std::memchr(from_p, '<', static_cast<std::size_t>(stop - from_p));
        j = static_cast<std::size_t>((lt ? static_cast<const char*>(lt) : stop) - p);
    }
    if (j < limit && p[j] == '>') return {j + 1, true, std::string_view(p + start, j + 1 - start)};
    if (j < limit) {  // '<' again before '>': resync there
        ++stats_.interrupted;
        return {j, false, {}};
    }
    if (n - start < max_element_) {  // runs past the chunk: keep it for the next feed
        buffer_.assign(p + start, n - start);
        in_element_ = true;
        return {n, false, {}};
    }
    ++stats_.overlong;  // K2: the cap is reached without '>'
    skipping_ = true;
    return {limit, false, {}};
}

std::size_t ElementParser::scan(std::span<const char> bytes) {
    const std::size_t n = bytes.size();
    std::size_t i = 0;
    while (i < n) {
        if (!in_element_) {
            // K1/K3: everything up to the next '<' is noise (or the tail of an
            // abandoned overlong element, which was already counted).
            const char c = bytes[i++];
            if (c == '<') {
                in_element_ = true;
                skipping_ = false;
                buffer_.assign(1, '<');
            } else if (!skipping_ && !is_blank(c)) {
                ++stats_.discarded_bytes;
            }
            continue;
        }
        // Inside an element: copy a run of ordinary bytes at once.
        std::size_t j = i;
        const std::size_t room = max_element_ - 1 - buffer_.size();  // keep space for '>'
        const std::size_t limit = std::min(n, i + room);
        while (j < limit && bytes[j] != '>' && bytes[j] != '<') ++j;
        buffer_.append(bytes.data() + i, j - i);
        i = j;
        if (i == n) break;
        const char c = bytes[i];
        if (c == '>') {
            buffer_.push_back('>');
            in_element_ = false;
            ready_ = true;
            return i + 1;
        }
        if (c == '<') {  // a new element starts before this one ended: resync there
            ++stats_.interrupted;
            buffer_.assign(1, '<');
            ++i;
            continue;
        }
        // K2: cap reached without '>'.
        ++stats_.overlong;
        buffer_.clear();
        in_element_ = false;
        skipping_ = true;
    }
    return n;
}

// ---- encoders ----------------------------------------------------------------

void encode_frame(const Frame& f, Nanos time_ns, std::string& out) {
    Writer w;
    if (f.flags & kFlagError) {
        w.text("< error ");
        w.hex(f.id & kMaxExtendedId, f.id > 0xFFF ? 8 : 3);
        w.ch(' ');
        w.time(time_ns);
        w.text(" >");
    } else if (f.rtr) {
        w.text("< rtr ");
        w.id(f);
        w.ch(' ');
        w.time(time_ns);
        w.ch(' ');
        w.uint(f.len);
        w.text(" >");
    } else {
        if (f.is_fd()) {
            w.text("< fdframe ");
            w.id(f);
            w.ch(' ');
            w.byte(fd_flags_byte(f));
        } else {
            w.text("< frame ");
            w.id(f);
        }
        w.ch(' ');
        w.time(time_ns);
        // Always a blank after the timestamp, even without data: socketcand writes
        // "< frame 123 1.000000  >" and python-can needs that empty data field.
        w.ch(' ');
        const std::size_t len = f.len > kMaxFdLen ? kMaxFdLen : f.len;
        for (std::size_t i = 0; i < len; ++i) w.byte(f.data[i]);
        w.text(" >");
    }
    w.flush_to(out);
}

void encode_error_text(std::string_view message, std::string& out) {
    out.append("< error ");
    for (char c : message.substr(0, 200)) out.push_back(c == '<' || c == '>' ? '?' : c);
    out.append(" >");
}

void encode_send(const Frame& f, std::string& out) {
    Writer w;
    const std::size_t len = f.len > kMaxFdLen ? kMaxFdLen : f.len;
    if (f.rtr) {
        w.text("< sendrtr ");
        w.id(f);
        w.ch(' ');
        w.uint(f.len);
        w.text(" >");
        w.flush_to(out);
        return;
    }
    if (f.is_fd()) {
        w.text("< fdsend ");
        w.id(f);
        w.ch(' ');
        w.byte(fd_flags_byte(f));
        w.ch(' ');
    } else {
        w.text("< send ");
        w.id(f);
        w.ch(' ');
    }
    w.uint(len);
    for (std::size_t i = 0; i < len; ++i) {
        w.ch(' ');
        w.byte(f.data[i]);
    }
    w.text(" >");
    w.flush_to(out);
}

void encode_command(ElementKind k, std::string& out) {
    out.append("< ");
    out.append(to_string(k));
    out.append(" >");
}

void encode_open(std::string_view channel, std::string& out) {
    out.append("< open ");
    out.append(channel.substr(0, kMaxChannelName));
    out.append(" >");
}

}  // namespace motorbus::can::socketcand
