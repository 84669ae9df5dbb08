#include "motorbus/canopen/od.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

bool readable(Access a) { return a != Access::WO; }
bool writable(Access a) { return a == Access::WO || a == Access::RW || a == Access::RWR || a == Access::RWW; }

const char* access_name(Access a) {
    switch (a) {
        case Access::RO: return "ro";
        case Access::WO: return "wo";
        case Access::RW: return "rw";
        case Access::RWR: return "rwr";
        case Access::RWW: return "rww";
        case Access::Const: return "const";
    }
    return "rw";
}

std::optional<Access> access_from_name(std::string_view s) {
    std::string l;
    for (char c : s)
        if (!std::isspace(static_cast<unsigned char>(c)))
            l.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    if (l == "ro") return Access::RO;
    if (l == "wo") return Access::WO;
    if (l == "rw") return Access::RW;
    if (l == "rwr") return Access::RWR;
    if (l == "rww") return Access::RWW;
    if (l == "const") return Access::Const;
    return std::nullopt;
}

namespace {
std::string where(const VariableSpec& s) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "0x%04X:%02X", s.index, s.subindex);
    return std::string(buf) + (s.name.empty() ? "" : " (" + s.name + ")");
}
}  // namespace

Variable::Variable(VariableSpec spec, std::size_t dictionary_max_size) : spec_(std::move(spec)) {
    const std::size_t fixed = type_size(spec_.type);
    max_size_ = fixed ? fixed : (spec_.max_size ? spec_.max_size : dictionary_max_size);
    if ((spec_.low_limit || spec_.high_limit) && !is_numeric(spec_.type))
        throw InvalidArgument(where(spec_) + ": limits need a numeric type, not " +
                              type_name(spec_.type));
    for (auto* lim : {&spec_.low_limit, &spec_.high_limit})
        if (*lim && !encode_scalar(spec_.type, **lim))
            throw InvalidArgument(where(spec_) + ": limit " + scalar_to_string(**lim) +
                                  " does not fit " + type_name(spec_.type));
    if (spec_.low_limit && spec_.high_limit &&
        compare_scalars(*spec_.low_limit, *spec_.high_limit) > 0)
        throw InvalidArgument(where(spec_) + ": low limit " + scalar_to_string(*spec_.low_limit) +
                              " is above high limit " + scalar_to_string(*spec_.high_limit));
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, std::monostate>) {
                default_.assign(fixed, 0);
            } else if constexpr (std::is_same_v<T, Bytes>) {
                if (fixed && v.size() != fixed)
                    throw InvalidArgument(where(spec_) + ": default has " + std::to_string(v.size()) +
                                          " bytes, the type needs " + std::to_string(fixed));
                if (!fixed && v.size() > max_size_)
                    throw InvalidArgument(where(spec_) + ": default is longer than max_size");
                default_ = v;
            } else {
                auto enc = encode_scalar(spec_.type, Scalar{v});
                if (!enc)
                    throw InvalidArgument(where(spec_) + ": default " + scalar_to_string(Scalar{v}) +
                                          " does not fit " + type_name(spec_.type));
                default_ = std::move(*enc);
            }
        },
        spec_.default_value);
    value_ = default_;
}

Bytes Variable::get() const {
    std::lock_guard lock(mutex_);
    return value_;
}

bool Variable::holds(std::span<const std::uint8_t> data) const {
    std::lock_guard lock(mutex_);
    return value_.size() == data.size() && (data.empty() || std::memcmp(value_.data(), data.data(), data.size()) == 0);
}

std::uint32_t Variable::check_size_for_write(std::size_t n) const {
    const std::size_t fixed = type_size(spec_.type);
    if (fixed && spec_.alt_size && n == spec_.alt_size) return 0;
    if (fixed) {
        if (n > fixed) return abort_code::kTooLong;
        if (n < fixed) return abort_code::kTooShort;
    } else if (n > max_size_) {
        return abort_code::kTooLong;
    }
    return 0;
}

std::optional<std::pair<Scalar, Scalar>> Variable::value_range() const {
    const DataType t = spec_.type;
    const std::size_t bits = 8 * type_size(t);
    std::optional<Scalar> lo, hi;
    if (t == DataType::Boolean) {
        lo = std::uint64_t{0};
        hi = std::uint64_t{1};
    } else if (is_signed(t) && bits) {
        lo = bits >= 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (bits - 1));
        hi = bits >= 64 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (bits - 1)) - 1;
    } else if (is_unsigned(t) && bits) {
        lo = std::uint64_t{0};
        hi = bits >= 64 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << bits) - 1;
    }
    if (spec_.low_limit) lo = spec_.low_limit;
    if (spec_.high_limit) hi = spec_.high_limit;
    if (!lo || !hi) return std::nullopt;
    return std::pair{*lo, *hi};
}

std::uint32_t Variable::validate(std::span<const std::uint8_t> data) const {
    if (auto c = check_size_for_write(data.size())) return c;
    if (spec_.type == DataType::Boolean && data[0] > 1) return abort_code::kInvalidValue;
    if (spec_.low_limit || spec_.high_limit) {
        auto v = decode_scalar(spec_.type, data);
        if (!v) return abort_code::kTypeMismatch;
        if (spec_.low_limit && compare_scalars(*v, *spec_.low_limit) < 0) return abort_code::kValueTooLow;
        if (spec_.high_limit && compare_scalars(*v, *spec_.high_limit) > 0) return abort_code::kValueTooHigh;
    }
    return 0;
}

void Variable::commit(std::span<const std::uint8_t> data) {
    std::lock_guard lock(mutex_);
    value_.assign(data.begin(), data.end());
}

void Variable::notify() const {
    // Called on every set: the usual single listener is copied without a vector.
    ChangeListener one;
    std::vector<ChangeListener> ls;
    {
        std::lock_guard lock(mutex_);
        if (listeners_.empty()) return;
        if (listeners_.size() == 1)
            one = listeners_.front().second;
        else
            for (auto& [h, cb] : listeners_) ls.push_back(cb);
    }
    if (one) {
        one(*this);
        return;
    }
    for (auto& cb : ls) cb(*this);
}

std::uint32_t Variable::try_set(std::span<const std::uint8_t> data) {
    if (auto c = validate(data)) return c;
    commit(data);
    notify();
    return 0;
}

void Variable::set(std::span<const std::uint8_t> data) {
    if (auto c = try_set(data)) throw InvalidArgument(where(spec_) + ": " + describe_abort(c));
}

Scalar Variable::get_scalar() const {
    auto v = decode_scalar(spec_.type, get());
    if (!v) throw InvalidArgument(where(spec_) + ": " + type_name(spec_.type) + " is not numeric");
    return *v;
}

std::int64_t Variable::get_i64() const {
    auto v = get_scalar();
    if (auto p = std::get_if<std::int64_t>(&v)) return *p;
    if (auto p = std::get_if<std::uint64_t>(&v)) return static_cast<std::int64_t>(*p);
    return static_cast<std::int64_t>(std::get<double>(v));
}

std::uint64_t Variable::get_u64() const {
    auto v = get_scalar();
    if (auto p = std::get_if<std::uint64_t>(&v)) return *p;
    if (auto p = std::get_if<std::int64_t>(&v)) return static_cast<std::uint64_t>(*p);
    return static_cast<std::uint64_t>(std::get<double>(v));
}

double Variable::get_f64() const {
    return std::visit([](auto x) { return static_cast<double>(x); }, get_scalar());
}

void Variable::set_scalar(const Scalar& v) {
    auto enc = encode_scalar(spec_.type, v);
    if (!enc)
        throw InvalidArgument(where(spec_) + ": " + scalar_to_string(v) + " does not fit " +
                              type_name(spec_.type));
    set(*enc);
}

std::string Variable::get_string() const {
    auto b = get();
    return std::string(b.begin(), b.end());
}

void Variable::reset_to_default() {
    commit(default_);
    notify();
}

std::uint32_t Variable::remote_read(Bytes& out) const {
    if (!readable(spec_.access)) return abort_code::kWriteOnly;
    ReadHook hook;
    {
        std::lock_guard lock(mutex_);
        out = value_;
        hook = read_hook_;
    }
    if (hook) {
        if (auto c = hook(*this, out)) return c;
        if (out.size() > max_size_) return abort_code::kOutOfMemory;
    }
    return 0;
}

std::uint32_t Variable::remote_write(std::span<const std::uint8_t> data) {
    if (!writable(spec_.access)) return abort_code::kReadOnly;
    Bytes resized;
    const std::size_t fixed = type_size(spec_.type);
    if (fixed && spec_.alt_size && data.size() == spec_.alt_size && data.size() != fixed) {
        for (std::size_t i = fixed; i < data.size(); ++i)
            if (data[i] != 0) return abort_code::kValueTooHigh;
        resized.assign(data.begin(), data.begin() + std::min(fixed, data.size()));
        resized.resize(fixed, 0);
        data = resized;
    }
    if (auto c = validate(data)) return c;
    WriteHook hook;
    {
        std::lock_guard lock(mutex_);
        hook = write_hook_;
    }
    if (hook)
        if (auto c = hook(*this, data)) return c;
    commit(data);
    notify();
    return 0;
}

void Variable::set_read_hook(ReadHook h) {
    std::lock_guard lock(mutex_);
    read_hook_ = std::move(h);
}
void Variable::set_write_hook(WriteHook h) {
    std::lock_guard lock(mutex_);
    write_hook_ = std::move(h);
}
void Variable::set_chunk_read_hook(ChunkReadHook h) {
    std::lock_guard lock(mutex_);
    chunk_hook_ = std::move(h);
}
ChunkReadHook Variable::chunk_read_hook() const {
    std::lock_guard lock(mutex_);
    return chunk_hook_;
}
bool Variable::has_hooks() const {
    std::lock_guard lock(mutex_);
    return read_hook_ || write_hook_ || chunk_hook_ || !listeners_.empty();
}

std::uint64_t Variable::add_change_listener(ChangeListener cb) {
    std::lock_guard lock(mutex_);
    listeners_.emplace_back(next_listener_, std::move(cb));
    return next_listener_++;
}
void Variable::remove_change_listener(std::uint64_t handle) {
    std::lock_guard lock(mutex_);
    std::erase_if(listeners_, [&](auto& p) { return p.first == handle; });
}

// ---------------------------------------------------------------------------

VariablePtr ObjectDictionary::add_variable(VariableSpec spec) {
    spec.subindex = 0;
    std::unique_lock lock(mutex_);
    if (objects_.count(spec.index)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "object 0x%04X already exists", spec.index);
        throw InvalidArgument(buf);
    }
    auto var = std::make_shared<Variable>(std::move(spec), max_variable_size_);
    Object obj;
    obj.index = var->index();
    obj.name = var->name();
    obj.code = ObjectCode::Var;
    obj.subs[0] = var;
    objects_.emplace(obj.index, std::move(obj));
    if (!var->name().empty()) by_name_[var->name()] = var;
    return var;
}

Object& ObjectDictionary::add_record(std::uint16_t index, std::string name, ObjectCode code) {
    if (code != ObjectCode::Record && code != ObjectCode::Array && code != ObjectCode::DefStruct)
        throw InvalidArgument("add_record: object code must be ARRAY, RECORD or DEFSTRUCT");
    std::unique_lock lock(mutex_);
    if (objects_.count(index)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "object 0x%04X already exists", index);
        throw InvalidArgument(buf);
    }
    Object obj;
    obj.index = index;
    obj.name = std::move(name);
    obj.code = code;
    obj.subs[0] = std::make_shared<Variable>(
        VariableSpec{.index = index, .subindex = 0, .name = "Highest sub-index supported",
                     .type = DataType::Unsigned8, .access = Access::RO,
                     .default_value = std::uint64_t{0}, .default_expr = "auto"},
        max_variable_size_);
    return objects_.emplace(index, std::move(obj)).first->second;
}

VariablePtr ObjectDictionary::add_member(std::uint16_t index, VariableSpec spec) {
    spec.index = index;
    std::unique_lock lock(mutex_);
    auto it = objects_.find(index);
    if (it == objects_.end() || it->second.code == ObjectCode::Var) {
        char buf[80];
        std::snprintf(buf, sizeof buf, "add_member: 0x%04X is not an ARRAY or RECORD", index);
        throw InvalidArgument(buf);
    }
    Object& obj = it->second;
    if (spec.subindex != 0 && obj.subs.count(spec.subindex)) {
        char buf[80];
        std::snprintf(buf, sizeof buf, "add_member: 0x%04X:%02X already exists", index, spec.subindex);
        throw InvalidArgument(buf);
    }
    auto var = std::make_shared<Variable>(std::move(spec), max_variable_size_);
    obj.subs[var->subindex()] = var;
    auto& sub0 = obj.subs[0];
    if (sub0->spec().default_expr == "auto" && var->subindex() != 0) {
        // Keep the automatic count equal to the highest member, default included.
        std::uint8_t highest = obj.subs.rbegin()->first;
        std::lock_guard vlock(sub0->mutex_);
        sub0->spec_.default_value = std::uint64_t{highest};
        sub0->default_ = {highest};
        sub0->value_ = {highest};
    }
    if (!var->name().empty()) by_name_[obj.name + "." + var->name()] = var;
    return var;
}

VariablePtr ObjectDictionary::find(std::uint16_t index, std::uint8_t subindex) const {
    std::shared_lock lock(mutex_);
    auto it = objects_.find(index);
    if (it == objects_.end()) return nullptr;
    return it->second.sub(subindex);
}

VariablePtr ObjectDictionary::at(std::uint16_t index, std::uint8_t subindex) const {
    if (auto v = find(index, subindex)) return v;
    char buf[64];
    std::snprintf(buf, sizeof buf, "object 0x%04X:%02X is not in the dictionary", index, subindex);
    throw InvalidArgument(buf);
}

std::uint32_t ObjectDictionary::lookup(std::uint16_t index, std::uint8_t subindex,
                                       VariablePtr& out) const {
    std::shared_lock lock(mutex_);
    auto it = objects_.find(index);
    if (it == objects_.end()) return abort_code::kNoObject;
    out = it->second.sub(subindex);
    return out ? 0 : abort_code::kNoSubindex;
}

namespace {
bool parse_hex(std::string_view s, unsigned long& v) {
    if (s.empty() || s.size() > 8) return false;
    auto r = std::from_chars(s.data(), s.data() + s.size(), v, 16);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
}  // namespace

VariablePtr ObjectDictionary::find(std::string_view name) const {
    {
        std::shared_lock lock(mutex_);
        if (auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    }
    // Numeric forms: "0x1018", "0x1018:1" (sub in decimal or 0x hex), "1018sub1".
    std::string_view idx = name, sub;
    bool hex_sub = true;
    if (auto p = name.find(':'); p != std::string_view::npos) {
        idx = name.substr(0, p);
        sub = name.substr(p + 1);
        hex_sub = false;
    } else if (auto q = name.find("sub"); q != std::string_view::npos) {
        idx = name.substr(0, q);
        sub = name.substr(q + 3);
    }
    if (idx.size() > 2 && idx[0] == '0' && (idx[1] == 'x' || idx[1] == 'X')) idx.remove_prefix(2);
    unsigned long i = 0, s = 0;
    if (!parse_hex(idx, i) || i > 0xFFFF) return nullptr;
    if (!sub.empty()) {
        if (sub.size() > 2 && sub[0] == '0' && (sub[1] == 'x' || sub[1] == 'X')) {
            sub.remove_prefix(2);
            hex_sub = true;
        }
        if (hex_sub) {
            if (!parse_hex(sub, s)) return nullptr;
        } else {
            auto r = std::from_chars(sub.data(), sub.data() + sub.size(), s, 10);
            if (r.ec != std::errc() || r.ptr != sub.data() + sub.size()) return nullptr;
        }
        if (s > 0xFF) return nullptr;
    }
    return find(static_cast<std::uint16_t>(i), static_cast<std::uint8_t>(s));
}

VariablePtr ObjectDictionary::at(std::string_view name) const {
    if (auto v = find(name)) return v;
    throw InvalidArgument("object '" + std::string(name) + "' is not in the dictionary");
}

std::optional<Object> ObjectDictionary::object(std::uint16_t index) const {
    std::shared_lock lock(mutex_);
    auto it = objects_.find(index);
    if (it == objects_.end()) return std::nullopt;
    return it->second;
}

std::vector<std::uint16_t> ObjectDictionary::indices() const {
    std::shared_lock lock(mutex_);
    std::vector<std::uint16_t> v;
    v.reserve(objects_.size());
    for (auto& [i, o] : objects_) v.push_back(i);
    return v;
}

std::size_t ObjectDictionary::size() const {
    std::shared_lock lock(mutex_);
    return objects_.size();
}

}  // namespace motorbus::canopen
