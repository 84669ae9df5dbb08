// Bindings for cpp/motorbus/canopen: object dictionary, EDS, SDO client,
// LocalNode, and the SDO errors (SdoAbortError, SdoTimeout, SdoProtocolError)
// through the error table of errors.hpp.
#include <cmath>
#include <limits>

#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "errors.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/abort_codes.hpp"
#include "motorbus/canopen/eds.hpp"
#include "motorbus/canopen/local_node.hpp"
#include "motorbus/canopen/od.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/sdo_poll_source.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;
using motorbus::py_helpers::Blocking;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::arg_cast;
using motorbus::py_helpers::py_type_name;

namespace {

py::handle g_abort;  // SdoAbortError: hooks may raise it to answer with its code

void fill_abort(py::object& exc, const SdoAbortError& e) {
    exc.attr("code") = e.code;
    exc.attr("text") = e.text();
    exc.attr("index") = e.index;
    exc.attr("subindex") = e.subindex;
}
void fill_timeout(py::object& exc, const SdoTimeout& e) {
    exc.attr("index") = e.index;
    exc.attr("subindex") = e.subindex;
}
void fill_protocol(py::object& exc, const SdoProtocolError& e) {
    exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
    exc.attr("code") = e.code;
    exc.attr("index") = e.index;
    exc.attr("subindex") = e.subindex;
}

py::bytes to_bytes(const Bytes& b) { return py::bytes(reinterpret_cast<const char*>(b.data()), b.size()); }

Bytes from_buffer(const py::object& o) {
    if (py::isinstance<py::str>(o)) {
        auto s = o.cast<std::string>();
        return Bytes(s.begin(), s.end());
    }
    if (!py::isinstance<py::bytes>(o) && !py::isinstance<py::bytearray>(o) && !py::isinstance<py::memoryview>(o) &&
        !PyObject_CheckBuffer(o.ptr()))
        throw InvalidArgument("data: expected bytes, bytearray, memoryview or str, got " + py_type_name(o));
    std::string s = py::bytes(o).cast<std::string>();
    return Bytes(s.begin(), s.end());
}

DataType type_from_py(const py::object& o) {
    if (py::isinstance<DataType>(o)) return o.cast<DataType>();
    if (py::isinstance<py::int_>(o)) {
        auto c = arg_cast<unsigned>(o, "data_type", "a DataType, its code or its name");
        if (c > 0xFFFF || !is_known_type(static_cast<std::uint16_t>(c)))
            throw InvalidArgument("data_type: 0x" + std::to_string(c) + " is not a CiA 301 basic type");
        return static_cast<DataType>(c);
    }
    std::string n = arg_cast<std::string>(o, "data_type", "a DataType, its code or its name");
    if (auto dt = data_type_from_name(n)) return *dt;
    throw InvalidArgument("data_type: '" + n + "' unknown (e.g. 'u32', 'UNSIGNED32', DataType.UNSIGNED32)");
}

Access access_from_py(const std::string& s) {
    if (auto a = access_from_name(s)) return *a;
    throw InvalidArgument("access: '" + s + "' unknown (ro, wo, rw, rwr, rww, const)");
}

std::optional<Scalar> scalar_from_py(const py::object& o) {
    if (o.is_none()) return std::nullopt;
    if (py::isinstance<py::float_>(o)) return Scalar{o.cast<double>()};
    py::int_ i = o;
    if (i < py::int_(0)) return Scalar{o.cast<std::int64_t>()};
    return Scalar{o.cast<std::uint64_t>()};
}

py::object scalar_to_py(const Scalar& s) {
    return std::visit([](auto v) -> py::object { return py::cast(v); }, s);
}

// A Python value for raw bytes of type `t`.
py::object value_to_py(DataType t, const Bytes& raw) {
    if (t == DataType::Boolean && raw.size() == 1) return py::bool_(raw[0] != 0);
    if (is_numeric(t)) {
        if (auto s = decode_scalar(t, raw)) return scalar_to_py(*s);
        return to_bytes(raw);
    }
    if (t == DataType::VisibleString) {
        std::string s(raw.begin(), raw.end());
        return py::reinterpret_steal<py::object>(PyUnicode_DecodeLatin1(s.data(), static_cast<Py_ssize_t>(s.size()), nullptr));
    }
    return to_bytes(raw);
}

// The bytes of `o` as type `t`; `what` names the value in the error.
Bytes value_from_py(DataType t, const py::object& o, const std::string& what) {
    if (is_numeric(t) && !py::isinstance<py::bytes>(o) && !py::isinstance<py::bytearray>(o)) {
        auto s = scalar_from_py(o);
        auto b = s ? encode_scalar(t, *s) : std::nullopt;
        if (!b) throw InvalidArgument(what + ": " + py::str(o).cast<std::string>() + " does not fit " + type_name(t));
        return *b;
    }
    return from_buffer(o);
}
py::object value_to_py(const Variable& v, const Bytes& raw) { return value_to_py(v.type(), raw); }
Bytes value_from_py(const Variable& v, const py::object& o) { return value_from_py(v.type(), o, v.name()); }

VariableSpec spec_from_py(std::uint16_t index, std::uint8_t sub, std::string name, const py::object& type,
                          const std::string& access, bool pdo, const py::object& low, const py::object& high,
                          const py::object& def, std::size_t max_size) {
    VariableSpec s;
    s.index = index;
    s.subindex = sub;
    s.name = std::move(name);
    s.type = type_from_py(type);
    s.access = access_from_py(access);
    s.pdo_mappable = pdo;
    s.low_limit = scalar_from_py(low);
    s.high_limit = scalar_from_py(high);
    s.max_size = max_size;
    if (!def.is_none()) {
        if (is_numeric(s.type) && !py::isinstance<py::bytes>(def)) {
            auto sc = *scalar_from_py(def);
            std::visit([&](auto x) { s.default_value = x; }, sc);
        } else {
            s.default_value = from_buffer(def);
        }
    }
    return s;
}

// Python callables called from C++ threads, with the GIL, returning an abort code.
std::uint32_t call_hook(const std::shared_ptr<py::function>& f, const py::object& a, const py::object& b) {
    py::gil_scoped_acquire gil;
    try {
        py::object r = (*f)(a, b);
        if (r.is_none()) return 0;
        return r.cast<std::uint32_t>();
    } catch (py::error_already_set& e) {
        if (e.matches(g_abort)) {
            try {
                return e.value().attr("code").cast<std::uint32_t>();
            } catch (...) {
            }
        }
        e.discard_as_unraisable("motorbus OD hook");
        return abort_code::kGeneral;
    }
}

std::shared_ptr<py::function> hold(py::function f) {
    return std::shared_ptr<py::function>(new py::function(std::move(f)), [](py::function* p) {
        if (!Py_IsInitialized()) return;
        py::gil_scoped_acquire gil;
        delete p;
    });
}

NmtState nmt_state_of(const std::string& s) {
    if (auto st = nmt_state_from_name(s)) return *st;
    throw InvalidArgument("NMT state: '" + s + "' unknown (OPERATIONAL, STOPPED, PRE-OPERATIONAL)");
}

std::string u64s(std::uint64_t v) { return std::to_string(v); }

// A LocalNode joins its worker on destruction, and the worker may be waiting
// for the GIL inside a Python hook: never destroy it while holding the GIL.
struct ReleaseGilDelete {
    void operator()(LocalNode* n) const {
        if (Py_IsInitialized() && PyGILState_Check()) {
            py::gil_scoped_release nogil;
            delete n;
        } else {
            delete n;
        }
    }
};
using LocalNodeHolder = std::unique_ptr<LocalNode, ReleaseGilDelete>;

TransferMode mode_of(bool block, bool segmented) {
    return block ? TransferMode::Block : segmented ? TransferMode::Segmented : TransferMode::Auto;
}

}  // namespace

static void bind_errors_and_types(py::module_& m) {
    // ---- errors (the table of errors.hpp) ---------------------------------------
    py_errors::add_error_classes({
        {"SdoAbortError", {"MotorbusError"},
         "An SDO transfer was aborted: .code (CiA 301 abort code), .text, .index, .subindex."},
        {"SdoTimeout", {"TimeoutError"},
         "No SDO response in time; the client sent abort 0x05040000 with the index and sub-index."},
        {"SdoProtocolError", {"ProtocolError"},
         "The server broke the SDO protocol; .data is its frame, .code the abort code we sent."},
    }, "motorbus.canopen");
    // Class-level defaults, so the attributes exist on instances made from Python too.
    for (const char* n : {"SdoAbortError", "SdoProtocolError"}) py_errors::error_class(n).attr("code") = 0;
    py_errors::error_class("SdoAbortError").attr("text") = "";
    for (const char* n : {"SdoAbortError", "SdoTimeout", "SdoProtocolError"}) {
        py_errors::error_class(n).attr("index") = 0;
        py_errors::error_class(n).attr("subindex") = 0;
    }
    g_abort = py_errors::error_class("SdoAbortError");  // owned by the module for the interpreter's life
    py_errors::translate<SdoAbortError, fill_abort>(py_errors::error_class("SdoAbortError"));
    py_errors::translate<SdoTimeout, fill_timeout>(py_errors::error_class("SdoTimeout"));
    py_errors::translate<SdoProtocolError, fill_protocol>(py_errors::error_class("SdoProtocolError"));

    m.def("abort_text", [](std::uint32_t c) -> py::object {
        const char* t = abort_text(c);
        return t ? py::object(py::str(t)) : py::none();
    }, py::arg("code"), "CiA 301 text for an SDO abort code (None if unknown).");
    py::dict codes;
    for (auto& e : abort_table()) codes[py::int_(e.code)] = e.text;
    m.attr("ABORT_CODES") = codes;

    // ---- data types ---------------------------------------------------------
    py::enum_<DataType> dt(m, "DataType", "CiA 301 basic data types (codes as in EDS files).");
    for (unsigned c = 1; c <= 0x1B; ++c)
        if (is_known_type(static_cast<std::uint16_t>(c)))
            dt.value(type_name(static_cast<DataType>(c)), static_cast<DataType>(c));
}

static void bind_variable(py::module_& m) {
    // ---- variables and the dictionary --------------------------------------
    py::class_<Variable, std::shared_ptr<Variable>>(m, "Variable", "One object-dictionary entry.")
        .def_property_readonly("index", &Variable::index)
        .def_property_readonly("subindex", &Variable::subindex)
        .def_property_readonly("name", &Variable::name)
        .def_property_readonly("data_type", &Variable::type)
        .def_property_readonly("access", [](const Variable& v) { return access_name(v.access()); })
        .def_property_readonly("pdo_mappable", &Variable::pdo_mappable)
        .def_property_readonly("size", &Variable::size, "fixed size in bytes; 0 for strings/domains")
        .def_property_readonly("low_limit", [](const Variable& v) -> py::object {
            return v.spec().low_limit ? scalar_to_py(*v.spec().low_limit) : py::none();
        })
        .def_property_readonly("high_limit", [](const Variable& v) -> py::object {
            return v.spec().high_limit ? scalar_to_py(*v.spec().high_limit) : py::none();
        })
        .def_property_readonly("default", [](const Variable& v) { return value_to_py(v, v.default_bytes()); })
        .def_property("raw", [](const Variable& v) { return to_bytes(v.get()); },
                      [](Variable& v, const py::object& o) { v.set(from_buffer(o)); },
                      "value as little-endian bytes")
        .def_property("value", [](const Variable& v) { return value_to_py(v, v.get()); },
                      [](Variable& v, const py::object& o) { v.set(value_from_py(v, o)); },
                      "value as int/float/bool/str/bytes by type (local write: limits checked, no hooks)")
        .def_property_readonly("value_range", [](const Variable& v) -> py::object {
            auto r = v.value_range();
            if (!r) return py::none();
            return py::make_tuple(scalar_to_py(r->first), scalar_to_py(r->second));
        }, "(low, high) a write may carry: the limits, else the integer type's range; None for other types")
        // The codec of this entry's type, for hosts (a node's SDO access, a vendor profile):
        // nothing outside the dictionary needs a table of type sizes.
        .def("encode", [](const Variable& v, const py::object& o) { return to_bytes(value_from_py(v, o)); },
             py::arg("value"), "The little-endian bytes of `value` as this entry's type (InvalidArgument if it "
                               "does not fit the type; the limits are the device's to enforce).")
        .def("decode", [](const Variable& v, const py::bytes& data) {
            std::string s = data;
            return value_to_py(v, Bytes(s.begin(), s.end()));
        }, py::arg("data"), "The Python value of `data` as this entry's type (int, float, bool, str or bytes).")
        .def("reset", &Variable::reset_to_default)
        .def("set_write_hook", [](Variable& v, py::object f) {
            if (f.is_none()) return v.set_write_hook(nullptr);
            auto h = hold(f.cast<py::function>());
            v.set_write_hook([h](const Variable& var, std::span<const std::uint8_t> d) {
                py::gil_scoped_acquire gil;
                auto self = py::cast(std::const_pointer_cast<Variable>(var.shared_from_this()));
                return call_hook(h, self, py::bytes(reinterpret_cast<const char*>(d.data()), d.size()));
            });
        }, py::arg("hook"),
             "hook(variable, data: bytes) -> None | abort code; called before a remote write commits.")
        .def("set_read_hook", [](Variable& v, py::object f) {
            if (f.is_none()) return v.set_read_hook(nullptr);
            auto h = hold(f.cast<py::function>());
            v.set_read_hook([h](const Variable& var, Bytes& out) -> std::uint32_t {
                py::gil_scoped_acquire gil;
                try {
                    py::object r = (*h)(py::cast(std::const_pointer_cast<Variable>(var.shared_from_this())),
                                        to_bytes(out));
                    if (r.is_none()) return 0;
                    if (py::isinstance<py::int_>(r)) return r.cast<std::uint32_t>();
                    out = value_from_py(var, r);
                    return 0;
                } catch (py::error_already_set& e) {
                    if (e.matches(g_abort)) return e.value().attr("code").cast<std::uint32_t>();
                    e.discard_as_unraisable("motorbus OD read hook");
                    return abort_code::kGeneral;
                }
            });
        }, py::arg("hook"),
             "hook(variable, current: bytes) -> None | new value | abort code; called on a remote read.")
        .def("add_change_listener", [](Variable& v, py::function f) {
            auto h = hold(std::move(f));
            return v.add_change_listener([h](const Variable& var) {
                py::gil_scoped_acquire gil;
                try {
                    (*h)(py::cast(std::const_pointer_cast<Variable>(var.shared_from_this())));
                } catch (py::error_already_set& e) {
                    e.discard_as_unraisable("motorbus OD listener");
                }
            });
        }, py::arg("callback"))
        .def("remove_change_listener", &Variable::remove_change_listener, py::arg("handle"))
        .def("__repr__", [](const Variable& v) {
            char b[96];
            std::snprintf(b, sizeof b, "<Variable 0x%04X:%02X %s %s>", v.index(), v.subindex(),
                          type_name(v.type()), access_name(v.access()));
            return std::string(b) + " '" + v.name() + "'";
        });
}

static void bind_object_dictionary(py::module_& m) {
    py::class_<ObjectDictionary, std::shared_ptr<ObjectDictionary>>(m, "ObjectDictionary",
        "Objects addressed by (index, subindex) or by name ('Record.Member', '0x1018:1').")
        .def(py::init<>())
        .def("add_variable",
             [](ObjectDictionary& od, std::uint16_t index, std::string name, const py::object& type,
                const std::string& access, bool pdo, const py::object& low, const py::object& high,
                const py::object& def, std::size_t max_size) {
                 return od.add_variable(spec_from_py(index, 0, std::move(name), type, access, pdo, low, high,
                                                     def, max_size));
             },
             py::arg("index"), py::arg("name"), py::arg("data_type"), py::arg("access") = "rw",
             py::arg("pdo_mappable") = false, py::arg("low") = py::none(), py::arg("high") = py::none(),
             py::arg("default") = py::none(), py::arg("max_size") = 0)
        .def("add_record", [](ObjectDictionary& od, std::uint16_t index, std::string name, bool array) {
                 od.add_record(index, std::move(name), array ? ObjectCode::Array : ObjectCode::Record);
             },
             py::arg("index"), py::arg("name"), py::arg("array") = false)
        .def("add_member",
             [](ObjectDictionary& od, std::uint16_t index, std::uint8_t sub, std::string name,
                const py::object& type, const std::string& access, bool pdo, const py::object& low,
                const py::object& high, const py::object& def, std::size_t max_size) {
                 return od.add_member(index, spec_from_py(index, sub, std::move(name), type, access, pdo,
                                                          low, high, def, max_size));
             },
             py::arg("index"), py::arg("subindex"), py::arg("name"), py::arg("data_type"),
             py::arg("access") = "rw", py::arg("pdo_mappable") = false, py::arg("low") = py::none(),
             py::arg("high") = py::none(), py::arg("default") = py::none(), py::arg("max_size") = 0)
        .def("__getitem__", [](const ObjectDictionary& od, const py::object& key) {
            if (py::isinstance<py::tuple>(key)) {
                auto t = key.cast<std::pair<std::uint16_t, std::uint8_t>>();
                return od.at(t.first, t.second);
            }
            if (py::isinstance<py::int_>(key)) return od.at(key.cast<std::uint16_t>(), 0);
            return od.at(key.cast<std::string>());
        })
        .def("__contains__", [](const ObjectDictionary& od, const py::object& key) {
            if (py::isinstance<py::tuple>(key)) {
                auto t = key.cast<std::pair<std::uint16_t, std::uint8_t>>();
                return od.find(t.first, t.second) != nullptr;
            }
            if (py::isinstance<py::int_>(key)) return od.object(key.cast<std::uint16_t>()).has_value();
            return od.find(key.cast<std::string>()) != nullptr;
        })
        .def("__len__", &ObjectDictionary::size)
        .def("indices", &ObjectDictionary::indices)
        .def("subindices", [](const ObjectDictionary& od, std::uint16_t i) {
            std::vector<std::uint8_t> v;
            if (auto o = od.object(i))
                for (auto& [s, var] : o->subs) v.push_back(s);
            return v;
        })
        .def("object_code", [](const ObjectDictionary& od, std::uint16_t i) -> py::object {
            auto o = od.object(i);
            if (!o) return py::none();
            return py::str(o->code == ObjectCode::Var || o->code == ObjectCode::Domain ? "VAR" : o->code == ObjectCode::Array ? "ARRAY" : "RECORD");
        }, py::arg("index"), "'VAR', 'RECORD' or 'ARRAY'; None when the index is not in the dictionary.")
        .def("object_name", [](const ObjectDictionary& od, std::uint16_t i) -> py::object {
            auto o = od.object(i);
            return o ? py::object(py::str(o->name)) : py::none();
        })
        .def_property("node_id", &ObjectDictionary::node_id, &ObjectDictionary::set_node_id)
        .def_property("max_variable_size", &ObjectDictionary::max_variable_size,
                      &ObjectDictionary::set_max_variable_size)
        .def_static("from_eds",
                    [](const std::string& path, std::uint8_t node_id, const py::object& warnings) {
                        std::vector<std::string> w;
                        EdsImportOptions o;
                        o.node_id = node_id;
                        auto od = load_eds(path, o, &w);
                        if (!warnings.is_none())
                            for (auto& s : w) warnings.attr("append")(s);
                        return od;
                    },
                    py::arg("path"), py::arg("node_id") = 0, py::arg("warnings") = py::none(),
                    "Load an EDS/DCF file; entries it cannot represent are appended to `warnings`.")
        .def_static("from_eds_text",
                    [](const std::string& text, std::uint8_t node_id, const py::object& warnings) {
                        std::vector<std::string> w;
                        EdsImportOptions o;
                        o.node_id = node_id;
                        auto od = parse_eds(text, o, &w);
                        if (!warnings.is_none())
                            for (auto& s : w) warnings.attr("append")(s);
                        return od;
                    },
                    py::arg("text"), py::arg("node_id") = 0, py::arg("warnings") = py::none())
        .def("to_eds", [](const ObjectDictionary& od, bool dcf) {
                 EdsExportOptions o;
                 o.dcf = dcf;
                 return to_eds(od, o);
             },
             py::arg("dcf") = false)
        .def("save_eds", [](const ObjectDictionary& od, const std::string& path, bool dcf) {
                 EdsExportOptions o;
                 o.dcf = dcf;
                 save_eds(od, path, o);
             },
             py::arg("path"), py::arg("dcf") = false);

    m.def("decode_value", [](DataType t, const py::bytes& data) {
              std::string s = data;
              return value_to_py(t, Bytes(s.begin(), s.end()));
          }, py::arg("data_type"), py::arg("data"),
          "The Python value of little-endian bytes of a CiA 301 type (int, float, bool, str or bytes).");
    m.def("encode_value", [](DataType t, const py::object& value) {
              return to_bytes(value_from_py(t, value, std::string("value of type ") + type_name(t)));
          }, py::arg("data_type"), py::arg("value"),
          "The little-endian bytes of `value` as a CiA 301 type; InvalidArgument when it does not fit.");
}

static void bind_counters(py::module_& m) {
    // ---- counters: C++ structs, read-only -------------------------------------------
    py::class_<SdoClientCounters>(m, "SdoClientCounters", "Counters of one SDO client, across its transfers.")
        .def_readonly("transfers", &SdoClientCounters::transfers)
        .def_readonly("aborts_received", &SdoClientCounters::aborts_received, "the server aborted")
        .def_readonly("aborts_sent", &SdoClientCounters::aborts_sent, "we aborted (timeout, protocol error)")
        .def_readonly("timeouts", &SdoClientCounters::timeouts)
        .def_readonly("ignored_frames", &SdoClientCounters::ignored_frames, "responses while idle, duplicates")
        .def_readonly("retransmit_requests", &SdoClientCounters::retransmit_requests,
                      "block: sub-blocks acknowledged short (lost frames)")
        .def_readonly("fallbacks", &SdoClientCounters::fallbacks, "block refused, retried segmented")
        .def_readonly("foreign_responses", &SdoClientCounters::foreign_responses,
                      "initiate responses / aborts naming another object: another client's on the same COB-IDs, ignored")
        .def("__repr__", [](const SdoClientCounters& c) {
            return "SdoClientCounters(transfers=" + u64s(c.transfers) + ", aborts_received=" + u64s(c.aborts_received) +
                   ", aborts_sent=" + u64s(c.aborts_sent) + ", timeouts=" + u64s(c.timeouts) + ", ignored_frames=" +
                   u64s(c.ignored_frames) + ", retransmit_requests=" + u64s(c.retransmit_requests) +
                   ", fallbacks=" + u64s(c.fallbacks) + ", foreign_responses=" + u64s(c.foreign_responses) + ")";
        });
    py::class_<SdoServerCounters>(m, "SdoServerCounters", "Counters of a LocalNode's SDO server.")
        .def_readonly("requests", &SdoServerCounters::requests)
        .def_readonly("responses", &SdoServerCounters::responses, "including aborts")
        .def_readonly("aborts_sent", &SdoServerCounters::aborts_sent)
        .def_readonly("aborts_received", &SdoServerCounters::aborts_received)
        .def_readonly("ignored", &SdoServerCounters::ignored, "DLC 0, stray block segments, duplicates")
        .def_readonly("timeouts", &SdoServerCounters::timeouts)
        .def_readonly("dropped", &SdoServerCounters::dropped, "requests dropped while the mailbox was full (S18)")
        .def_readonly("transfers_completed", &SdoServerCounters::transfers_completed)
        .def("__repr__", [](const SdoServerCounters& c) {
            return "SdoServerCounters(requests=" + u64s(c.requests) + ", responses=" + u64s(c.responses) +
                   ", aborts_sent=" + u64s(c.aborts_sent) + ", aborts_received=" + u64s(c.aborts_received) +
                   ", ignored=" + u64s(c.ignored) + ", timeouts=" + u64s(c.timeouts) + ", dropped=" +
                   u64s(c.dropped) + ", transfers_completed=" + u64s(c.transfers_completed) + ")";
        });
    py::class_<LocalNodeCounters>(m, "LocalNodeCounters", "Counters of a LocalNode: its SDO server and NMT.")
        .def_readonly("sdo", &LocalNodeCounters::sdo)
        .def_readonly("nmt_commands", &LocalNodeCounters::nmt_commands, "applied")
        .def_readonly("nmt_ignored", &LocalNodeCounters::nmt_ignored, "wrong DLC, other node, unknown command")
        .def_readonly("sdo_while_stopped", &LocalNodeCounters::sdo_while_stopped)
        .def_readonly("sdo_bad_dlc", &LocalNodeCounters::sdo_bad_dlc, "SDO requests with DLC != 8 dropped (sdo_require_dlc8)")
        .def("__repr__", [](const LocalNodeCounters& c) {
            return "LocalNodeCounters(nmt_commands=" + u64s(c.nmt_commands) + ", nmt_ignored=" + u64s(c.nmt_ignored) +
                   ", sdo_while_stopped=" + u64s(c.sdo_while_stopped) + ", sdo=" +
                   py::repr(py::cast(c.sdo)).cast<std::string>() + ")";
        });
}

static void bind_sdo_client(py::module_& m) {
    // ---- SDO client --------------------------------------------------------------
    py::class_<SdoClient>(m, "SdoClient", "SDO client for one node (requests 0x600+n, responses 0x580+n).")
        .def(py::init([](can::Bus& bus, std::uint8_t node_id, double timeout, std::size_t max_transfer,
                         std::uint8_t block_size, unsigned read_retries, std::uint32_t request_id,
                         std::uint32_t response_id, bool block_fallback, bool block_crc) {
                 SdoClientOptions o;
                 o.fallback_to_segmented = block_fallback;
                 o.block_crc = block_crc;
                 // 0 would time every transfer out before its first response; inf waits
                 // forever (Ctrl-C still ends it).
                 if (timeout == 0) throw InvalidArgument("SdoClient timeout: must be > 0 s (inf = wait forever)");
                 o.timeout = finite_forever(duration_arg(timeout, "timeout", Forever::Allowed));
                 o.max_transfer = max_transfer;
                 o.block_size = block_size;
                 o.read_retries = read_retries;
                 o.request_id = request_id;
                 o.response_id = response_id;
                 return std::make_unique<SdoClient>(bus, node_id, o);
             }),
             py::arg("bus"), py::arg("node_id"), py::arg("timeout") = 1.0, py::arg("max_transfer") = 1u << 20,
             py::arg("block_size") = 127, py::arg("read_retries") = 0, py::arg("request_id") = 0,
             py::arg("response_id") = 0, py::arg("block_fallback") = false, py::arg("block_crc") = true,
             py::keep_alive<1, 2>(),
             "block_crc: block transfers offer and require CRC-16 (a server answering without it is "
             "refused, abort 0x05040004); False for a server without CRC, whose block data is then unchecked.")
        .def("upload", [](SdoClient& c, std::uint16_t i, std::uint8_t s, bool block) {
                 Bytes b;
                 b = blocking_call([&] { return c.upload(i, s, block ? TransferMode::Block : TransferMode::Auto); });
                 return to_bytes(b);
             },
             py::arg("index"), py::arg("subindex") = 0, py::arg("block") = false)
        .def("download", [](SdoClient& c, std::uint16_t i, std::uint8_t s, const py::object& data, bool block,
                            bool segmented) {
                 Bytes b = from_buffer(data);
                 blocking_call([&] { c.download(i, s, b, mode_of(block, segmented)); });
             },
             py::arg("index"), py::arg("subindex"), py::arg("data"), py::arg("block") = false,
             py::arg("segmented") = false)
#define MB_RW(T, name)                                                                         \
    .def("read_" #name, &Blocking<&SdoClient::read_##name>::call, py::arg("index"),            \
         py::arg("subindex") = 0)                                                              \
    .def("write_" #name, &Blocking<&SdoClient::write_##name>::call, py::arg("index"),          \
         py::arg("subindex"), py::arg("value"))
        MB_RW(std::uint8_t, u8) MB_RW(std::uint16_t, u16) MB_RW(std::uint32_t, u32) MB_RW(std::uint64_t, u64)
        MB_RW(std::int8_t, i8) MB_RW(std::int16_t, i16) MB_RW(std::int32_t, i32) MB_RW(std::int64_t, i64)
        MB_RW(double, f64)
#undef MB_RW
        .def("read_f32", &Blocking<&SdoClient::read_f32>::call, py::arg("index"), py::arg("subindex") = 0)
        .def("write_f32", [](SdoClient& c, std::uint16_t i, std::uint8_t s, double v) {
                 // A Python float is a double: past the float range the cast stored inf.
                 // inf and nan themselves are REAL32 values and pass.
                 if (std::isfinite(v) && std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max()))
                     throw InvalidArgument("write_f32 value: " + py::repr(py::float_(v)).cast<std::string>() +
                                           " is outside the REAL32 range (|v| <= 3.4028235e38)");
                 blocking_call([&] { c.write_f32(i, s, static_cast<float>(v)); });
             },
             py::arg("index"), py::arg("subindex"), py::arg("value"))
        .def("read_string", &Blocking<&SdoClient::read_string>::call, py::arg("index"), py::arg("subindex") = 0)
        .def("write_string", [](SdoClient& c, std::uint16_t i, std::uint8_t s, const std::string& v) {
                 blocking_call([&] { c.write_string(i, s, v); });
             },
             py::arg("index"), py::arg("subindex"), py::arg("value"))
        .def("read_domain", [](SdoClient& c, std::uint16_t i, std::uint8_t s, bool block) {
                 Bytes b;
                 b = blocking_call([&] { return c.upload(i, s, block ? TransferMode::Block : TransferMode::Auto); });
                 return to_bytes(b);
             },
             py::arg("index"), py::arg("subindex") = 0, py::arg("block") = false)
        .def("write_domain", [](SdoClient& c, std::uint16_t i, std::uint8_t s, const py::object& data, bool block) {
                 Bytes b = from_buffer(data);
                 blocking_call([&] { c.download(i, s, b, block ? TransferMode::Block : TransferMode::Auto); });
             },
             py::arg("index"), py::arg("subindex"), py::arg("data"), py::arg("block") = false)
        .def_property("timeout",
                      [](const SdoClient& c) {
                          auto t = c.options().timeout;
                          return t >= py_helpers::kFiniteForever ? std::numeric_limits<double>::infinity()
                                                                 : static_cast<double>(t.count()) / 1e9;
                      },
                      [](SdoClient& c, const py::object& t) {
                          auto ns = finite_forever(duration_arg(t, "timeout", Forever::Allowed));
                          py::gil_scoped_release nogil;
                          c.set_timeout(ns);
                      },
                      "Seconds per response; inf (or None) = wait forever (Ctrl-C still interrupts).")
        .def_property_readonly("node_id", &SdoClient::node_id)
        .def_property_readonly("request_id", &SdoClient::request_id)
        .def_property_readonly("response_id", &SdoClient::response_id)
        .def_property_readonly("counters", &SdoClient::counters)
        // Completion-based transfers (motorbus.canopen's awaitable face): they return
        // at once, the GIL kept -- nothing here waits, and the C++ side completing
        // them never takes it (cpp/motorbus/canopen/sdo_client.hpp).
        .def("upload_async",
             [](SdoClient& c, std::uint16_t i, std::uint8_t s, std::shared_ptr<Completions> done,
                std::uint64_t token, bool block) {
                 c.upload_async(i, s, block ? TransferMode::Block : TransferMode::Auto, std::move(done), token);
             },
             py::arg("index"), py::arg("subindex"), py::arg("completions"), py::arg("token"),
             py::arg("block") = false, "Starts an upload; completes `token` on `completions` with its bytes.")
        .def("download_async",
             [](SdoClient& c, std::uint16_t i, std::uint8_t s, const py::object& data,
                std::shared_ptr<Completions> done, std::uint64_t token, bool block, bool segmented) {
                 Bytes b = from_buffer(data);
                 c.download_async(i, s, b, mode_of(block, segmented), std::move(done), token);
             },
             py::arg("index"), py::arg("subindex"), py::arg("data"), py::arg("completions"), py::arg("token"),
             py::arg("block") = false, py::arg("segmented") = false,
             "Starts a download; completes `token` on `completions` with None.")
        .def("check_deadline",
             [](SdoClient& c) -> py::object {
                 const Nanos next = c.check_deadline();
                 return next == kNoDeadline ? py::object(py::none()) : py::object(py::int_(next));
             },
             "Fires the running async transfer's due timers; the next deadline (monotonic_ns) or None.")
        .def("cancel_async", &SdoClient::cancel, py::arg("completions"), py::arg("token"),
             "Withdraws an async transfer (the running one is aborted on the wire); False if already done.")
        .def_property_readonly("async_pending", &SdoClient::async_pending)
        .def("close", &SdoClient::close,
             "Fails pending async transfers with ClosedError; later transfers raise ClosedError.")
        .def_property_readonly("closed", &SdoClient::closed);

    // A PollSource reading objects by SDO through this client (motorbus.Poller).
    m.def("sdo_poll_source",
          [](SdoClient& sdo, const std::vector<std::tuple<std::uint16_t, std::uint8_t, std::string>>& objects)
              -> std::shared_ptr<poll::Source> {
              std::vector<SdoPollObject> v;
              for (const auto& [index, sub, type] : objects) v.push_back({index, sub, type});
              return std::make_shared<SdoPollSource>(sdo, std::move(v));
          },
          py::arg("sdo"), py::arg("objects"), py::keep_alive<0, 1>(),
          "A PollSource uploading [(index, subindex, type)] each sample (type: 'i32', 'u16', ...).");
}

static void bind_local_node(py::module_& m) {
    // ---- LocalNode ---------------------------------------------------------------
    py::class_<LocalNode, LocalNodeHolder>(m, "LocalNode",
        "A node we serve: SDO server on 0x600+n/0x580+n, boot-up, NMT slave.")
        .def(py::init([](can::Bus& bus, std::uint8_t node_id, std::shared_ptr<ObjectDictionary> od,
                         double sdo_timeout, bool block_transfer, bool send_boot_up) {
                 LocalNodeOptions o;
                 o.sdo.timeout_ns = duration_arg(sdo_timeout, "sdo_timeout").count();
                 if (o.sdo.timeout_ns <= 0) throw InvalidArgument("sdo_timeout: must be > 0 seconds");
                 o.sdo.block_transfer = block_transfer;
                 o.send_boot_up = send_boot_up;
                 py::gil_scoped_release nogil;
                 return LocalNodeHolder(new LocalNode(bus, node_id, std::move(od), o));
             }),
             py::arg("bus"), py::arg("node_id"), py::arg("od"), py::arg("sdo_timeout") = 1.0,
             py::arg("block_transfer") = true, py::arg("send_boot_up") = true, py::keep_alive<1, 2>())
        .def_property_readonly("node_id", &LocalNode::node_id)
        .def_property_readonly("od", &LocalNode::od_ptr)
        .def_property("nmt_state", [](const LocalNode& n) { return to_string(n.nmt_state()); },
                      [](LocalNode& n, const std::string& s) {
                          auto st = nmt_state_of(s);
                          py::gil_scoped_release nogil;
                          n.set_nmt_state(st);
                      })
        .def("add_state_listener", [](LocalNode& n, py::function f) {
                 auto h = hold(std::move(f));
                 return n.add_state_listener([h](NmtState a, NmtState b) {
                     py::gil_scoped_acquire gil;
                     try {
                         (*h)(to_string(a), to_string(b));
                     } catch (py::error_already_set& e) {
                         e.discard_as_unraisable("motorbus NMT listener");
                     }
                 });
             },
             py::arg("callback"), "callback(previous: str, now: str) on every NMT transition")
        .def("remove_state_listener", &LocalNode::remove_state_listener, py::arg("handle"))
        .def("send_boot_up", &LocalNode::send_boot_up, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("counters", &LocalNode::counters)
        .def("close", &LocalNode::close, py::call_guard<py::gil_scoped_release>())
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](LocalNode& n, py::args) {
            py::gil_scoped_release nogil;
            n.close();
        });
}

void bind_canopen(py::module_& m) {
    bind_errors_and_types(m);
    bind_variable(m);
    bind_object_dictionary(m);
    bind_counters(m);
    bind_sdo_client(m);
    bind_local_node(m);
}
