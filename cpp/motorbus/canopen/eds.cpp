#include "motorbus/canopen/eds.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "motorbus/errors.hpp"

namespace motorbus::canopen {

namespace {

std::string lower(std::string_view s) {
    std::string r(s);
    for (auto& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

using Section = std::map<std::string, std::string>;  // lower-case key -> raw value

struct Ini {
    std::map<std::string, Section> sections;  // lower-case name
    std::vector<std::string> order;
    const Section* get(const std::string& name) const {
        auto it = sections.find(lower(name));
        return it == sections.end() ? nullptr : &it->second;
    }
};

Ini parse_ini(std::string_view text) {
    Ini ini;
    Section* cur = nullptr;
    std::size_t line_no = 0;
    while (!text.empty()) {
        auto nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
        ++line_no;
        line = trim(line);
        if (line.empty() || line[0] == ';' || line[0] == '#') continue;
        if (line[0] == '[') {
            auto close = line.find(']');
            if (close == std::string_view::npos)
                throw InvalidArgument("EDS line " + std::to_string(line_no) + ": unterminated section name");
            std::string name = lower(trim(line.substr(1, close - 1)));
            if (!ini.sections.count(name)) ini.order.push_back(name);
            cur = &ini.sections[name];
            continue;
        }
        auto eq = line.find('=');
        if (eq == std::string_view::npos || !cur)
            throw InvalidArgument("EDS line " + std::to_string(line_no) + ": expected key=value in a section");
        (*cur)[lower(trim(line.substr(0, eq)))] = std::string(trim(line.substr(eq + 1)));
    }
    return ini;
}

std::optional<std::uint64_t> parse_uint_literal(std::string_view s) {
    s = trim(s);
    int base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    } else if (s.size() > 1 && s[0] == '0') {
        base = 8;
        s.remove_prefix(1);
    }
    if (s.empty()) return std::nullopt;
    std::uint64_t v = 0;
    auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
    return v;
}

std::optional<std::int64_t> parse_int_literal(std::string_view s) {
    s = trim(s);
    bool neg = false;
    if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
        neg = s[0] == '-';
        s.remove_prefix(1);
    }
    // The magnitude follows the sign directly: "- 5" is not a number.
    if (s.empty() || std::isspace(static_cast<unsigned char>(s.front()))) return std::nullopt;
    const auto v = parse_uint_literal(s);
    if (!v) return std::nullopt;
    if (neg) {
        if (*v > (std::uint64_t{1} << 63)) return std::nullopt;
        return static_cast<std::int64_t>(0 - *v);
    }
    return static_cast<std::int64_t>(*v);  // values >= 2^63 wrap; callers re-read as unsigned
}

std::string hex(unsigned v, int width) {
    char b[16];
    std::snprintf(b, sizeof b, "%0*X", width, v);
    return b;
}

}  // namespace

std::optional<std::int64_t> eval_eds_integer(std::string_view expr, std::uint8_t node_id,
                                             bool* uses_node_id) {
    expr = trim(expr);
    if (uses_node_id) *uses_node_id = false;
    if (expr.empty()) return std::nullopt;
    std::int64_t total = 0;
    std::size_t start = 0;
    // Terms joined by '+'; a leading sign belongs to the first literal.
    for (std::size_t i = 0; i <= expr.size(); ++i) {
        if (i < expr.size() && !(expr[i] == '+' && i > start)) continue;
        std::string_view term = trim(expr.substr(start, i - start));
        start = i + 1;
        if (lower(term) == "$nodeid") {
            total += node_id;
            if (uses_node_id) *uses_node_id = true;
        } else if (auto v = parse_int_literal(term)) {
            total += *v;
        } else {
            return std::nullopt;
        }
    }
    return total;
}

namespace {

struct Importer {
    const Ini& ini;
    std::uint8_t node_id;
    bool use_pv;
    std::vector<std::string>* warnings;
    ObjectDictionary& od;

    void warn(const std::string& w) {
        if (warnings) warnings->push_back(w);
    }

    // Builds a VariableSpec from a section; nullopt (with a warning) if it cannot.
    std::optional<VariableSpec> spec_from(const Section& s, const std::string& where, std::uint16_t index,
                                          std::uint8_t sub, const Section* parent, std::string name) {
        auto val = [&](const char* k) -> const std::string* {
            if (auto it = s.find(k); it != s.end()) return &it->second;
            if (parent)
                if (auto it = parent->find(k); it != parent->end()) return &it->second;
            return nullptr;
        };
        VariableSpec spec;
        spec.index = index;
        spec.subindex = sub;
        spec.name = std::move(name);
        const std::string* dt = val("datatype");
        auto code = dt ? parse_uint_literal(*dt) : std::nullopt;
        if (!code || !is_known_type(static_cast<std::uint16_t>(*code)) || *code > 0xFFFF) {
            warn(where + ": data type " + (dt ? *dt : std::string("missing")) + " not supported, skipped");
            return std::nullopt;
        }
        spec.type = static_cast<DataType>(*code);
        if (const std::string* a = val("accesstype")) {
            if (auto acc = access_from_name(*a)) spec.access = *acc;
            else warn(where + ": access type '" + *a + "' unknown, using rw");
        }
        if (const std::string* m = val("pdomapping")) spec.pdo_mappable = parse_uint_literal(*m).value_or(0) != 0;
        auto number = [&](const std::string& text, bool* nid) -> std::optional<Scalar> {
            if (is_real(spec.type)) {
                std::string t(trim(text));
                if (t.empty()) return std::nullopt;
                char* end = nullptr;
                double d = std::strtod(t.c_str(), &end);
                if (end != t.c_str() + t.size()) return std::nullopt;
                return Scalar{d};
            }
            auto v = eval_eds_integer(text, node_id, nid);
            if (!v) return std::nullopt;
            if (is_unsigned(spec.type)) {
                if (*v < 0 && !nid) return std::nullopt;
                if (auto u = parse_uint_literal(text); u && !(nid && *nid)) return Scalar{*u};
                return Scalar{static_cast<std::uint64_t>(*v)};
            }
            return Scalar{*v};
        };
        if (is_numeric(spec.type)) {
            std::optional<Scalar> lo, hi;
            if (const std::string* l = val("lowlimit"); l && !trim(*l).empty()) lo = number(*l, nullptr);
            if (const std::string* h = val("highlimit"); h && !trim(*h).empty()) hi = number(*h, nullptr);
            if (lo && !encode_scalar(spec.type, *lo)) lo.reset();
            if (hi && !encode_scalar(spec.type, *hi)) hi.reset();
            if (lo && hi && compare_scalars(*lo, *hi) > 0) {
                warn(where + ": LowLimit above HighLimit, limits ignored");
                lo.reset();
                hi.reset();
            }
            spec.low_limit = lo;
            spec.high_limit = hi;
        }
        if (const std::string* d = val("defaultvalue"); d && !trim(*d).empty()) {
            if (is_numeric(spec.type)) {
                bool nid = false;
                auto v = number(*d, &nid);
                if (v && encode_scalar(spec.type, *v)) {
                    std::visit([&](auto x) { spec.default_value = x; }, *v);
                    if (nid) spec.default_expr = *d;
                } else {
                    warn(where + ": DefaultValue '" + *d + "' does not fit " + type_name(spec.type) +
                         ", using 0");
                }
            } else if (spec.type == DataType::OctetString || spec.type == DataType::Domain) {
                std::string digits;
                for (char c : *d)
                    if (std::isxdigit(static_cast<unsigned char>(c))) digits.push_back(c);
                Bytes b;
                for (std::size_t i = 0; i + 1 < digits.size(); i += 2)
                    b.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
                spec.default_value = b;
            } else {
                spec.default_value = Bytes(d->begin(), d->end());
            }
        }
        return spec;
    }

    void apply_parameter_value(const Section& s, const VariablePtr& var, const std::string& where) {
        if (!use_pv || !var) return;
        auto it = s.find("parametervalue");
        if (it == s.end() || trim(it->second).empty()) return;
        Section tmp = s;
        tmp["defaultvalue"] = it->second;
        tmp.erase("lowlimit");
        tmp.erase("highlimit");
        auto spec = spec_from(tmp, where, var->index(), var->subindex(), nullptr, var->name());
        if (!spec) return;
        try {
            Variable probe(*spec, od.max_variable_size());
            if (var->try_set(probe.default_bytes()))
                warn(where + ": ParameterValue '" + it->second + "' refused, default kept");
        } catch (const Error&) {
            warn(where + ": ParameterValue '" + it->second + "' unusable");
        }
    }

    void import_object(std::uint16_t index, const Section& s) {
        char wbuf[16];
        std::snprintf(wbuf, sizeof wbuf, "[%04X]", index);
        const std::string where = wbuf;
        std::string name = s.count("parametername") ? s.at("parametername") : "";
        auto ot = s.count("objecttype") ? parse_uint_literal(s.at("objecttype")) : std::optional<std::uint64_t>{7};
        const std::uint64_t code = ot.value_or(7);
        try {
            if (code == 7 || code == 2) {  // VAR, DOMAIN
                auto spec = spec_from(s, where, index, 0, nullptr, name);
                if (code == 2 && !spec) {
                    Section d = s;
                    d["datatype"] = "0x000F";
                    spec = spec_from(d, where, index, 0, nullptr, name);
                }
                if (!spec) return;
                auto var = od.add_variable(*spec);
                apply_parameter_value(s, var, where);
                return;
            }
            if (code != 8 && code != 9) {
                warn(where + ": object type " + std::to_string(code) + " not supported, skipped");
                return;
            }
            od.add_record(index, name, code == 8 ? ObjectCode::Array : ObjectCode::Record);
            if (auto cs = s.find("compactsubobj"); cs != s.end() && parse_uint_literal(cs->second).value_or(0) > 0) {
                // Array described once: members 1..N share the main entry's type and access.
                const auto n = std::min<std::uint64_t>(parse_uint_literal(cs->second).value_or(0), 254);
                const Section* names = ini.get(hex(index, 4) + "name");
                for (std::uint64_t k = 1; k <= n; ++k) {
                    std::string member = name + " " + std::to_string(k);
                    if (names)
                        if (auto it = names->find(std::to_string(k)); it != names->end()) member = it->second;
                    auto spec = spec_from(s, where + "sub" + std::to_string(k), index,
                                          static_cast<std::uint8_t>(k), nullptr, member);
                    if (spec) od.add_member(index, *spec);
                }
                return;
            }
            for (unsigned sub = 0; sub <= 0xFF; ++sub) {
                char key[16];
                std::snprintf(key, sizeof key, "%04xsub%x", index, sub);
                const Section* ss = ini.get(key);
                if (!ss) continue;
                char swbuf[24];
                std::snprintf(swbuf, sizeof swbuf, "[%04Xsub%X]", index, sub);
                const std::string sw = swbuf;
                std::string member = ss->count("parametername") ? ss->at("parametername") : "";
                auto spec = spec_from(*ss, sw, index, static_cast<std::uint8_t>(sub), nullptr, member);
                if (!spec) continue;
                od.add_member(index, *spec);
                apply_parameter_value(*ss, od.find(index, static_cast<std::uint8_t>(sub)), sw);
            }
        } catch (const InvalidArgument& e) {
            warn(where + ": " + e.what());
        }
    }
};

}  // namespace

std::shared_ptr<ObjectDictionary> parse_eds(std::string_view text, const EdsImportOptions& options,
                                            std::vector<std::string>* warnings) {
    Ini ini = parse_ini(text);
    auto od = std::make_shared<ObjectDictionary>();
    std::uint8_t node_id = options.node_id;
    if (const Section* dc = ini.get("DeviceComissioning"); dc && node_id == 0)
        if (auto it = dc->find("nodeid"); it != dc->end())
            if (auto v = parse_uint_literal(it->second); v && *v >= 1 && *v <= 127)
                node_id = static_cast<std::uint8_t>(*v);
    od->set_node_id(node_id);

    auto& info = od->device_info();
    auto str = [](const Section* s, const char* k) -> std::string {
        if (!s) return {};
        auto it = s->find(k);
        return it == s->end() ? std::string{} : it->second;
    };
    auto num = [&](const Section* s, const char* k) {
        return static_cast<std::uint32_t>(parse_uint_literal(str(s, k)).value_or(0));
    };
    if (const Section* fi = ini.get("FileInfo")) {
        info.file_name = str(fi, "filename");
        info.description = str(fi, "description");
    }
    if (const Section* di = ini.get("DeviceInfo")) {
        info.vendor_name = str(di, "vendorname");
        info.vendor_number = num(di, "vendornumber");
        info.product_name = str(di, "productname");
        info.product_number = num(di, "productnumber");
        info.revision_number = num(di, "revisionnumber");
        info.order_code = str(di, "ordercode");
        info.baud_rates_kbit.clear();
        for (unsigned b : {10u, 20u, 50u, 125u, 250u, 500u, 800u, 1000u})
            if (num(di, ("baudrate_" + std::to_string(b)).c_str())) info.baud_rates_kbit.push_back(b);
        info.simple_boot_up_slave = num(di, "simplebootupslave") != 0;
        info.granularity = num(di, "granularity");
        info.nr_rx_pdo = num(di, "nrofrxpdo");
        info.nr_tx_pdo = num(di, "nroftxpdo");
        info.lss_supported = num(di, "lss_supported") != 0;
    }

    Importer imp{ini, node_id, options.use_parameter_values, warnings, *od};
    std::size_t objects = 0;
    for (const auto& name : ini.order) {
        if (name.size() != 4) continue;
        auto idx = parse_uint_literal("0x" + name);
        if (!idx || *idx == 0) continue;
        ++objects;
        imp.import_object(static_cast<std::uint16_t>(*idx), ini.sections.at(name));
    }
    if (objects == 0) throw InvalidArgument("EDS: no object sections ([1000], [2000], ...) found");
    return od;
}

std::shared_ptr<ObjectDictionary> load_eds(const std::string& path, const EdsImportOptions& options,
                                           std::vector<std::string>* warnings) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InvalidArgument("EDS: cannot read '" + path + "'");
    // Read at most the cap plus one byte: a bigger (or endless: /dev/zero, a
    // FIFO) file is refused without reading further or growing past the cap.
    std::string text;
    std::size_t have = 0;
    constexpr std::size_t kChunk = 64 * 1024;
    while (f && have <= kMaxEdsFileBytes) {
        text.resize(std::min(have + kChunk, kMaxEdsFileBytes + 1));
        f.read(text.data() + have, static_cast<std::streamsize>(text.size() - have));
        have += static_cast<std::size_t>(f.gcount());
    }
    if (have > kMaxEdsFileBytes)
        throw InvalidArgument("EDS: '" + path + "' is larger than the " +
                              std::to_string(kMaxEdsFileBytes >> 20) +
                              " MiB an EDS/DCF file may have (kMaxEdsFileBytes); not read further");
    if (f.bad()) throw InvalidArgument("EDS: cannot read '" + path + "'");
    text.resize(have);
    return parse_eds(text, options, warnings);
}

namespace {

std::string value_text(const Variable& v, const Bytes& raw) {
    const DataType t = v.type();
    if (is_numeric(t)) {
        auto s = decode_scalar(t, raw);
        if (!s) return "";
        if (auto u = std::get_if<std::uint64_t>(&*s)) {
            char b[24];
            std::snprintf(b, sizeof b, "0x%llX", static_cast<unsigned long long>(*u));
            return b;
        }
        return scalar_to_string(*s);
    }
    if (t == DataType::VisibleString) {
        std::string s(raw.begin(), raw.end());
        for (auto& c : s)
            if (c == '\n' || c == '\r') c = ' ';
        return s;
    }
    std::string h;
    char b[4];
    for (auto x : raw) {
        std::snprintf(b, sizeof b, "%02X", x);
        h += b;
    }
    return h;
}

void write_var(std::ostringstream& o, const std::string& section, const Variable& v, bool dcf) {
    o << "[" << section << "]\n";
    o << "ParameterName=" << v.name() << "\n";
    o << "ObjectType=0x7\n";
    o << "DataType=0x" << hex(static_cast<unsigned>(v.type()), 4) << "\n";
    o << "AccessType=" << access_name(v.access()) << "\n";
    const auto& spec = v.spec();
    if (spec.low_limit) {
        auto b = encode_scalar(v.type(), *spec.low_limit);
        if (b) o << "LowLimit=" << value_text(v, *b) << "\n";
    }
    if (spec.high_limit) {
        auto b = encode_scalar(v.type(), *spec.high_limit);
        if (b) o << "HighLimit=" << value_text(v, *b) << "\n";
    }
    if (!spec.default_expr.empty() && spec.default_expr != "auto")
        o << "DefaultValue=" << spec.default_expr << "\n";
    else if (!(v.type() == DataType::Domain && v.default_bytes().empty()))
        o << "DefaultValue=" << value_text(v, v.default_bytes()) << "\n";
    o << "PDOMapping=" << (v.pdo_mappable() ? 1 : 0) << "\n";
    if (dcf && v.type() != DataType::Domain) o << "ParameterValue=" << value_text(v, v.get()) << "\n";
    o << "\n";
}

}  // namespace

std::string to_eds(const ObjectDictionary& od, const EdsExportOptions& options) {
    std::ostringstream o;
    const auto& info = od.device_info();
    o << "[FileInfo]\n";
    o << "FileName=" << (info.file_name.empty() ? std::string(options.dcf ? "motorbus.dcf" : "motorbus.eds")
                                                : info.file_name)
      << "\n";
    o << "FileVersion=1\nFileRevision=0\nEDSVersion=4.0\n";
    o << "Description=" << info.description << "\n";
    o << "CreatedBy=motorbus\n\n";
    o << "[DeviceInfo]\n";
    o << "VendorName=" << info.vendor_name << "\n";
    o << "VendorNumber=0x" << hex(info.vendor_number, 8) << "\n";
    o << "ProductName=" << info.product_name << "\n";
    o << "ProductNumber=0x" << hex(info.product_number, 8) << "\n";
    o << "RevisionNumber=0x" << hex(info.revision_number, 8) << "\n";
    o << "OrderCode=" << info.order_code << "\n";
    for (unsigned b : {10u, 20u, 50u, 125u, 250u, 500u, 800u, 1000u})
        o << "BaudRate_" << b << "="
          << (std::find(info.baud_rates_kbit.begin(), info.baud_rates_kbit.end(), b) !=
                      info.baud_rates_kbit.end()
                  ? 1
                  : 0)
          << "\n";
    o << "SimpleBootUpMaster=0\nSimpleBootUpSlave=" << (info.simple_boot_up_slave ? 1 : 0) << "\n";
    o << "Granularity=" << info.granularity << "\n";
    o << "DynamicChannelsSupported=0\nGroupMessaging=0\n";
    o << "NrOfRXPDO=" << info.nr_rx_pdo << "\nNrOfTXPDO=" << info.nr_tx_pdo << "\n";
    o << "LSS_Supported=" << (info.lss_supported ? 1 : 0) << "\n\n";
    if (options.dcf) {
        const unsigned nid = options.node_id ? options.node_id : od.node_id();
        o << "[DeviceComissioning]\nNodeID=" << nid << "\nNodeName=" << info.product_name
          << "\nBaudRate=0\nNetNumber=0\n\n";
    }
    const auto indices = od.indices();
    std::vector<std::uint16_t> mandatory, optional, manufacturer;
    for (auto i : indices) {
        if (i == 0x1000 || i == 0x1001 || i == 0x1018) mandatory.push_back(i);
        else if (i >= 0x2000 && i <= 0x5FFF) manufacturer.push_back(i);
        else optional.push_back(i);
    }
    auto list = [&](const char* name, const std::vector<std::uint16_t>& v) {
        o << "[" << name << "]\nSupportedObjects=" << v.size() << "\n";
        for (std::size_t k = 0; k < v.size(); ++k) o << (k + 1) << "=0x" << hex(v[k], 4) << "\n";
        o << "\n";
    };
    list("MandatoryObjects", mandatory);
    list("OptionalObjects", optional);
    list("ManufacturerObjects", manufacturer);
    for (auto i : indices) {
        auto obj = od.object(i);
        if (!obj) continue;
        if (obj->code == ObjectCode::Var || obj->code == ObjectCode::Domain) {
            if (auto v = obj->sub(0)) write_var(o, hex(i, 4), *v, options.dcf);
            continue;
        }
        o << "[" << hex(i, 4) << "]\n";
        o << "ParameterName=" << obj->name << "\n";
        o << "ObjectType=0x" << hex(static_cast<unsigned>(obj->code), 1) << "\n";
        o << "SubNumber=0x" << hex(static_cast<unsigned>(obj->subs.size()), 1) << "\n\n";
        for (auto& [sub, var] : obj->subs) write_var(o, hex(i, 4) + "sub" + hex(sub, 1), *var, options.dcf);
    }
    return o.str();
}

void save_eds(const ObjectDictionary& od, const std::string& path, const EdsExportOptions& options) {
    std::ofstream f(path, std::ios::binary);
    if (!f) throw InvalidArgument("EDS: cannot write '" + path + "'");
    f << to_eds(od, options);
}

}  // namespace motorbus::canopen
