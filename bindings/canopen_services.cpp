// Bindings for the CANopen services: NMT, heartbeat, EMCY, SYNC, TIME, PDO,
// CiA 402 and the network scanner.  Thin: conversion, GIL release, lifetimes.
//
// Services are bound as themselves (shared_ptr holders made by make_service):
// the holder's deleter owns the bus, clock or SDO client the service refers
// to, and destroys the service with the GIL released, because unsubscribing
// or joining a timer thread waits for a callback that may itself be waiting
// for the GIL.  Counters and statuses are the C++ structs, read-only.
#include <pybind11/functional.h>
#include <pybind11/native_enum.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/cia402.hpp"
#include "motorbus/canopen/emcy.hpp"
#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/canopen/heartbeat_service.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_capture_source.hpp"
#include "motorbus/canopen/pdo_engine.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/scanner.hpp"
#include "motorbus/canopen/sdo_client_access.hpp"
#include "motorbus/canopen/sync.hpp"
#include "motorbus/canopen/time.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::py_helpers::PyCallable;
using motorbus::py_helpers::seconds_to_ns;
using motorbus::py_helpers::duration_arg;
using motorbus::py_helpers::finite_forever;
using motorbus::py_helpers::Forever;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::not_none;

namespace {

using BusPtr = std::shared_ptr<can::Bus>;
using ClockPtr = std::shared_ptr<Clock>;

// `keep` (bus, clock, SDO client...) outlives the service: it is released
// with the deleter, after the service is deleted.
template <class T, class Keep, class... A>
std::shared_ptr<T> make_service(Keep keep, A&&... args) {
    return std::shared_ptr<T>(new T(std::forward<A>(args)...), [keep = std::move(keep)](T* p) {
        if (PyGILState_Check()) {
            py::gil_scoped_release nogil;
            delete p;
        } else {
            delete p;
        }
    });
}

ClockPtr clock_or_real(const ClockPtr& c) { return c ? c : std::make_shared<RealClock>(); }

// A blocking call's timeout: None/inf = forever (a finite 31 years for the core).
std::chrono::nanoseconds timeout_of(const py::object& t) {
    return finite_forever(duration_arg(t, "timeout", Forever::Allowed));
}

py::bytes to_bytes(std::span<const std::uint8_t> b) {
    return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
}

std::vector<std::uint8_t> from_bytes(const py::bytes& b) {
    std::string s = b;
    return {s.begin(), s.end()};
}

// SdoAccess over a Python object with upload(index, sub) -> bytes and
// download(index, sub, data): lets any SDO client (our SdoClient binding, a
// python `canopen` SdoClient wrapper, a fake) serve the services.
class PySdoAccess : public SdoAccess {
public:
    explicit PySdoAccess(py::object o) : o_(std::move(o)) {}
    ~PySdoAccess() override {
        py::gil_scoped_acquire gil;
        o_ = py::object();
    }
    void download(std::uint8_t, std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> d) override {
        py::gil_scoped_acquire gil;
        o_.attr("download")(index, sub, to_bytes(d));
    }
    std::vector<std::uint8_t> upload(std::uint8_t, std::uint16_t index, std::uint8_t sub) override {
        py::gil_scoped_acquire gil;
        py::object r = o_.attr("upload")(index, sub);
        return from_bytes(py::bytes(r));
    }

private:
    py::object o_;
};

// Either a Bus (an SdoClient per node is made) or a duck-typed client.
struct SdoBox {
    BusPtr bus;
    py::object client;  // keeps a bound SdoClient alive
    std::shared_ptr<SdoAccess> access;
};
SdoBox make_sdo(const py::object& o, int node) {
    SdoBox b;
    if (py::isinstance<SdoClient>(o)) {
        // Our own client: called directly in C++, no GIL round trip.
        b.client = o;
        b.access = std::make_shared<ClientSdoAccess>(o.cast<SdoClient&>(), static_cast<std::uint8_t>(node));
    } else if (py::isinstance<can::Bus>(o)) {
        b.bus = o.cast<BusPtr>();
        b.access = std::make_shared<BusSdoAccess>(*b.bus);
    } else if (py::hasattr(o, "upload") && py::hasattr(o, "download")) {
        b.access = std::make_shared<PySdoAccess>(o);
    } else {
        throw InvalidArgument("sdo: pass a motorbus Bus or an object with upload()/download()");
    }
    return b;
}

std::vector<PdoMapEntry> entries_from(const py::iterable& it) {
    std::vector<PdoMapEntry> v;
    for (auto h : it) {
        auto t = h.cast<py::tuple>();
        if (t.size() < 3 || t.size() > 4)
            throw InvalidArgument("PDO mapping entry: (index, subindex, bits[, signed])");
        PdoMapEntry e;
        e.index = t[0].cast<std::uint16_t>();
        e.sub = t[1].cast<std::uint8_t>();
        const int bits = t[2].cast<int>();
        if (bits < 1 || bits > 64) throw InvalidArgument("PDO mapping entry: bits must be 1-64");
        e.bits = static_cast<std::uint8_t>(bits);
        e.is_signed = t.size() == 4 && t[3].cast<bool>();
        v.push_back(e);
    }
    return v;
}

py::list entries_to(const std::vector<PdoMapEntry>& v) {
    py::list l;
    for (auto& e : v) l.append(py::make_tuple(e.index, e.sub, e.bits));
    return l;
}

std::string hex(unsigned v, int width) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%0*X", width, v);
    return b;
}

std::string opt_hex(const std::optional<std::uint32_t>& v) { return v ? hex(*v, 8) : "None"; }

// The C++ codecs parse the names; these only turn "not a name" into the error.
NodeState node_state_of(const std::string& s) {
    if (auto st = node_state_from_name(s)) return *st;
    throw InvalidArgument("NMT state: expected INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL; got '" + s + "'");
}

Cia402State cia402_state_of(const std::string& s) {
    if (auto st = cia402_state_from_name(s)) return *st;
    throw InvalidArgument("CiA 402 state name not known: '" + s + "'");
}

// An int for a core function that range-checks it, narrowed to the core's
// type: a value the type cannot hold becomes the type's maximum, which each
// such check here refuses (SYNC counter 1-240, overflow 0 or 2-240, node range
// 1-127), so the range is checked once, by the core, with its message.
template <class U>
U saturate(std::int64_t v) {
    constexpr auto hi = std::numeric_limits<U>::max();
    return v < 0 || v > static_cast<std::int64_t>(hi) ? hi : static_cast<U>(v);
}

void check_node(int n, bool allow_zero) {
    if (n < (allow_zero ? 0 : 1) || n > 127)
        throw InvalidArgument("node id " + std::to_string(n) + (allow_zero ? " is outside 0-127" : " is outside 1-127"));
}

}  // namespace

static void bind_records(py::module_& m) {
    // ---- records: C++ structs, read-only --------------------------------------------
    py::class_<EmcyMessage>(m, "EmcyError", "One EMCY message as received (CiA 301).")
        .def_readonly("node", &EmcyMessage::node_id)
        .def_readonly("code", &EmcyMessage::code, "emergency error code (EEC)")
        .def_readonly("register", &EmcyMessage::error_register, "error register (0x1001) as sent")
        .def_property_readonly("data", [](const EmcyMessage& e) { return to_bytes(e.manufacturer); },
                               "manufacturer-specific bytes (5)")
        .def_readonly("short", &EmcyMessage::short_frame, "the frame had fewer than 8 bytes (missing ones read as 0)")
        .def_readonly("timestamp_ns", &EmcyMessage::timestamp_ns)
        .def_property_readonly("text", [](const EmcyMessage& e) { return emcy_code_text(e.code); })
        .def_property_readonly("is_reset", &EmcyMessage::is_reset, "EEC 0x0000: the node's errors are cleared")
        .def("__repr__", [](const EmcyMessage& e) {
            return "EmcyError(node=" + std::to_string(e.node_id) + ", code=" + hex(e.code, 4) + ", register=" +
                   hex(e.error_register, 2) + ", text='" + emcy_code_text(e.code) + "'" +
                   (e.short_frame ? ", short=True)" : ")");
        });

    py::class_<NodeHealth>(m, "NodeHealth", "What a heartbeat consumer knows about one node.")
        .def_readonly("node", &NodeHealth::node_id)
        .def_property_readonly("state", [](const NodeHealth& h) { return std::string(to_string(h.state)); })
        .def_readonly("raw_state", &NodeHealth::raw_state)
        .def_readonly("alive", &NodeHealth::alive, "heard within the consumer time")
        .def_readonly("lost", &NodeHealth::lost, "timed out and not heard since")
        .def_readonly("last_seen_ns", &NodeHealth::last_seen)
        .def_readonly("heartbeats", &NodeHealth::heartbeats)
        .def_readonly("boot_ups", &NodeHealth::boot_ups)
        .def_readonly("timeouts", &NodeHealth::timeouts)
        .def("__repr__", [](const NodeHealth& h) {
            return "NodeHealth(node=" + std::to_string(h.node_id) + ", state='" + to_string(h.state) +
                   "', alive=" + (h.alive ? "True" : "False") + ", lost=" + (h.lost ? "True" : "False") +
                   ", heartbeats=" + std::to_string(h.heartbeats) + ", boot_ups=" + std::to_string(h.boot_ups) +
                   ", timeouts=" + std::to_string(h.timeouts) + ")";
        });

    py::class_<JitterStats>(m, "JitterStats", "SYNC period error (actual - nominal) over the last periods.")
        .def_readonly("count", &JitterStats::count, "periods measured")
        .def_readonly("min_ns", &JitterStats::min_ns)
        .def_readonly("mean_ns", &JitterStats::mean_ns)
        .def_readonly("max_ns", &JitterStats::max_ns)
        .def_readonly("p99_abs_ns", &JitterStats::p99_abs_ns, "99th percentile of the error's magnitude")
        .def_readonly("max_abs_ns", &JitterStats::max_abs_ns)
        .def("__repr__", [](const JitterStats& j) {
            char b[160];
            std::snprintf(b, sizeof b, "JitterStats(count=%llu, min_ns=%.0f, mean_ns=%.0f, max_ns=%.0f, p99_abs_ns=%.0f)",
                          static_cast<unsigned long long>(j.count), j.min_ns, j.mean_ns, j.max_ns, j.p99_abs_ns);
            return std::string(b);
        });

    py::class_<PdoEngine::Counters>(m, "PdoCounters", "Counters of a served node's PDO engine.")
        .def_readonly("tpdo_sent", &PdoEngine::Counters::tpdo_sent)
        .def_readonly("rpdo_applied", &PdoEngine::Counters::rpdo_applied)
        .def_readonly("rpdo_ignored", &PdoEngine::Counters::rpdo_ignored)
        .def_readonly("rpdo_length_errors", &PdoEngine::Counters::rpdo_length_errors)
        .def_readonly("sync_received", &PdoEngine::Counters::sync_received)
        .def_readonly("sync_errors", &PdoEngine::Counters::sync_errors)
        .def_readonly("rtr_ignored", &PdoEngine::Counters::rtr_ignored)
        .def_readonly("collisions", &PdoEngine::Counters::collisions)
        .def("__repr__", [](const PdoEngine::Counters& c) {
            return "PdoCounters(tpdo_sent=" + std::to_string(c.tpdo_sent) + ", rpdo_applied=" +
                   std::to_string(c.rpdo_applied) + ", rpdo_ignored=" + std::to_string(c.rpdo_ignored) +
                   ", rpdo_length_errors=" + std::to_string(c.rpdo_length_errors) + ", sync_received=" +
                   std::to_string(c.sync_received) + ")";
        });

    py::class_<PdoConfig>(m, "PdoConfig", "A PDO's communication parameters and mapping as read from a device.")
        .def_readonly("tpdo", &PdoConfig::tpdo)
        .def_readonly("number", &PdoConfig::number)
        .def_readonly("cob_id", &PdoConfig::cob_id)
        .def_readonly("enabled", &PdoConfig::enabled)
        .def_readonly("transmission_type", &PdoConfig::transmission_type)
        .def_readonly("inhibit_100us", &PdoConfig::inhibit_100us)
        .def_readonly("event_timer_ms", &PdoConfig::event_timer_ms)
        .def_readonly("sync_start", &PdoConfig::sync_start)
        .def_property_readonly("mapping", [](const PdoConfig& c) {
            return c.mapping ? entries_to(*c.mapping) : py::list();
        }, "[(index, subindex, bits), ...]")
        .def("__repr__", [](const PdoConfig& c) {
            std::string map;
            if (c.mapping)
                for (auto& e : *c.mapping)
                    map += (map.empty() ? "" : ", ") + hex(e.index, 4) + ":" + std::to_string(e.sub) + "/" +
                           std::to_string(e.bits);
            return std::string("PdoConfig(") + (c.tpdo ? "tpdo=" : "rpdo=") + std::to_string(c.number) +
                   ", cob_id=" + opt_hex(c.cob_id) + ", enabled=" + (c.enabled ? "True" : "False") +
                   ", mapping=[" + map + "])";
        });

    py::class_<ScanResult>(m, "NodeInfo", "A node found by scan_network().")
        .def_readonly("node", &ScanResult::node_id)
        .def_readonly("sdo_answered", &ScanResult::sdo_answered, "any SDO reply (value or abort)")
        .def_readonly("heard_heartbeat", &ScanResult::heard_heartbeat)
        .def_readonly("heard_boot_up", &ScanResult::heard_boot_up)
        .def_property_readonly("state", [](const ScanResult& r) { return std::string(to_string(r.state)); })
        .def_readonly("device_type", &ScanResult::device_type, "0x1000")
        .def_readonly("device_type_abort", &ScanResult::device_type_abort, "abort code when 0x1000 was refused")
        .def_readonly("vendor_id", &ScanResult::vendor_id)
        .def_readonly("product_code", &ScanResult::product_code)
        .def_readonly("revision", &ScanResult::revision)
        .def_readonly("serial_number", &ScanResult::serial_number)
        .def_property_readonly("profile", [](const ScanResult& r) -> std::optional<std::uint16_t> {
            if (!r.device_type) return std::nullopt;
            return r.profile();
        }, "device profile number (402 for drives) from 0x1000's low 16 bits")
        .def("__repr__", [](const ScanResult& r) {
            return "NodeInfo(node=" + std::to_string(r.node_id) + ", state='" + to_string(r.state) +
                   "', device_type=" + opt_hex(r.device_type) + ", vendor_id=" + opt_hex(r.vendor_id) + ")";
        });
}

static void bind_codecs(py::module_& m) {
    // ---- pure codecs --------------------------------------------------------
    // An enum.IntEnum (not py::enum_): it replaces the IntEnum motorbus.canopen.nmt
    // defined before, whose members are ints (== 0x01, usable as a byte).
    py::native_enum<NmtCommand>(m, "NmtCommand", "enum.IntEnum", "NMT command specifiers (CiA 301).")
        .value("START", NmtCommand::Start)
        .value("STOP", NmtCommand::Stop)
        .value("ENTER_PRE_OPERATIONAL", NmtCommand::EnterPreOperational)
        .value("RESET_NODE", NmtCommand::ResetNode)
        .value("RESET_COMMUNICATION", NmtCommand::ResetCommunication)
        .finalize();
    py::enum_<PdoProcedure>(m, "PdoProcedure", "How pdo_write_config writes a PDO.")
        .value("CIA301", PdoProcedure::Cia301, "disable, parameters, clear sub0, entries, set sub0, enable")
        .value("DIRECT", PdoProcedure::Direct, "COB-ID, parameters, sub0 = n, entries (no disable/enable)");

    m.def("nmt_encode", [](NmtCommand cs, int node) {
              check_node(node, true);
              return encode_nmt(cs, static_cast<std::uint8_t>(node));
          }, py::arg("command"), py::arg("node"));
    m.def("nmt_encode", [](int cs, int node) {
              if (!is_known_nmt_command(static_cast<std::uint8_t>(cs)) || cs < 0 || cs > 255)
                  throw InvalidArgument("NMT command specifier must be 0x01, 0x02, 0x80, 0x81 or 0x82");
              check_node(node, true);
              return encode_nmt(static_cast<NmtCommand>(cs), static_cast<std::uint8_t>(node));
          }, py::arg("command"), py::arg("node"));
    m.def("nmt_decode", [](const can::Frame& f) -> py::object {
              auto d = decode_nmt(f);
              if (!d) return py::none();
              return py::make_tuple(d->command, d->node_id);
          }, py::arg("frame"), "(command, node) or None for anything that is not a valid NMT frame.");
    m.def("heartbeat_encode", [](int node, const std::string& state) {
              check_node(node, false);
              return encode_heartbeat(static_cast<std::uint8_t>(node), node_state_of(state));
          }, py::arg("node"), py::arg("state"));
    m.def("heartbeat_decode", [](const can::Frame& f) -> py::object {
              auto d = decode_heartbeat(f);
              if (!d) return py::none();
              return py::make_tuple(d->node_id, to_string(d->state), d->raw_state);
          }, py::arg("frame"), "(node, state name, raw byte) or None (DLC != 1, bad id).");
    m.def("emcy_encode", [](int node, std::uint16_t code, std::uint8_t reg, const py::bytes& data) {
              check_node(node, false);
              auto d = from_bytes(data);
              if (d.size() > 5) throw InvalidArgument("EMCY manufacturer data: at most 5 bytes");
              std::array<std::uint8_t, 5> msef{};
              std::copy(d.begin(), d.end(), msef.begin());
              return encode_emcy(static_cast<std::uint8_t>(node), code, reg, msef);
          }, py::arg("node"), py::arg("code"), py::arg("register") = 0, py::arg("data") = py::bytes());
    m.def("emcy_decode", [](const can::Frame& f) -> py::object {
              auto d = decode_emcy(f);
              if (!d) return py::none();
              return py::cast(*d);
          }, py::arg("frame"));
    m.def("emcy_code_text", &emcy_code_text, py::arg("code"));
    m.def("sync_encode", [](std::optional<int> counter, std::uint32_t cob_id) {
              return encode_sync(counter ? std::optional<std::uint8_t>(saturate<std::uint8_t>(*counter)) : std::nullopt,
                                 cob_id);  // the core refuses a counter outside 1-240
          }, py::arg("counter") = py::none(), py::arg("cob_id") = kSyncCobId);
    m.def("time_encode", [](std::int64_t unix_ms) { return encode_time(TimeOfDay::from_unix_ms(unix_ms)); },
          py::arg("unix_ms"));
    m.def("time_decode", [](const can::Frame& f) -> py::object {
              auto t = decode_time(f);
              if (!t) return py::none();
              return py::int_(t->to_unix_ms());
          }, py::arg("frame"), "Unix time in ms, or None.");
}

static void bind_nmt(py::module_& m) {
    // ---- NMT master -----------------------------------------------------------
    // Wrapped by motorbus.canopen.nmt.NmtMaster, which carries the docstrings.
    py::class_<NmtMaster, std::shared_ptr<NmtMaster>>(m, "NmtMaster")
        .def(py::init([](BusPtr bus, std::optional<int> own) {
                 not_none(bus, "bus");
                 if (own) check_node(*own, false);
                 return make_service<NmtMaster>(bus, *bus, own ? std::optional<std::uint8_t>(static_cast<std::uint8_t>(*own))
                                                               : std::nullopt);
             }), py::arg("bus"), py::arg("own_node_id") = py::none())
        .def("send", [](NmtMaster& b, NmtCommand cs, int node) {
                 check_node(node, true);
                 py::gil_scoped_release nogil;
                 b.send(cs, static_cast<std::uint8_t>(node));
             }, py::arg("command"), py::arg("node"))
        .def("send", [](NmtMaster& b, int cs, int node) {
                 if (cs < 0 || cs > 255 || !is_known_nmt_command(static_cast<std::uint8_t>(cs)))
                     throw InvalidArgument("NMT command specifier must be 0x01, 0x02, 0x80, 0x81 or 0x82");
                 check_node(node, true);
                 py::gil_scoped_release nogil;
                 b.send(static_cast<NmtCommand>(cs), static_cast<std::uint8_t>(node));
             }, py::arg("command"), py::arg("node"))
        .def("state", [](NmtMaster& b, int node) { check_node(node, false); return to_string(b.state(static_cast<std::uint8_t>(node))); }, py::arg("node"))
        .def("raw_state", [](NmtMaster& b, int node) { check_node(node, false); return b.raw_state(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("wait_for_state", [](NmtMaster& b, int node, const std::string& st, const py::object& t) {
                 check_node(node, false);
                 auto want = node_state_of(st);
                 auto to = timeout_of(t);
                 return blocking_call([&] { return b.wait_for_state(static_cast<std::uint8_t>(node), want, to); });
             }, py::arg("node"), py::arg("state"), py::arg("timeout") = 1.0)
        .def("set_state", [](NmtMaster& b, int node, const std::string& state) {
                 check_node(node, true);
                 auto c = nmt_command_for_state(state);
                 if (!c)
                     throw InvalidArgument("NMT state to command: '" + state +
                                           "' (OPERATIONAL, PRE-OPERATIONAL, STOPPED, RESET, RESET COMMUNICATION)");
                 py::gil_scoped_release nogil;
                 b.send(*c, static_cast<std::uint8_t>(node));
             }, py::arg("node"), py::arg("state"))
        .def("wait_for_heartbeat", [](NmtMaster& b, int node, const py::object& t) -> std::optional<std::string> {
                 check_node(node, false);
                 auto to = timeout_of(t);
                 std::optional<NodeState> s;
                 s = blocking_call([&] { return b.wait_for_heartbeat(static_cast<std::uint8_t>(node), to); });
                 if (!s) return std::nullopt;
                 return std::string(to_string(*s));
             }, py::arg("node"), py::arg("timeout") = 1.0)
        .def("wait_for_boot", [](NmtMaster& b, int node, const py::object& t) {
                 check_node(node, false);
                 auto to = timeout_of(t);
                 return blocking_call([&] { return b.wait_for_boot(static_cast<std::uint8_t>(node), to); });
             }, py::arg("node"), py::arg("timeout") = 1.0)
        .def("set_callback", [](NmtMaster& b, py::object cb) {
                 if (cb.is_none()) { b.on_state_change = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.on_state_change = [call](std::uint8_t n, NodeState a, NodeState c) {
                     call(n, std::string(to_string(a)), std::string(to_string(c)));
                 };
             }, py::arg("callback"))
        .def_property_readonly("foreign_commands_ignored", [](NmtMaster& b) { return b.foreign_commands_ignored(); });

    py::class_<NmtEventWait, std::shared_ptr<NmtEventWait>>(m, "NmtEventWait",
        "An awaited NMT event of one node (motorbus.canopen.nmt's *_async waits).")
        .def("cancel", [](NmtEventWait& w) { py::gil_scoped_release nogil; w.cancel(); });
    m.def("nmt_wait_async",
          [](BusPtr bus, int node, const std::optional<std::string>& state, bool boot_up,
             std::shared_ptr<Completions> done, std::uint64_t token) {
              not_none(bus, "bus");
              check_node(node, false);
              auto want = boot_up ? NmtEventWait::Want::BootUp
                                  : state ? NmtEventWait::Want::State : NmtEventWait::Want::AnyHeartbeat;
              return NmtEventWait::start(std::move(bus), static_cast<std::uint8_t>(node), want,
                                         state ? node_state_of(*state) : NodeState::Unknown, std::move(done), token);
          },
          py::arg("bus"), py::arg("node"), py::arg("state") = py::none(), py::arg("boot_up") = false,
          py::arg("completions"), py::arg("token"),
          "Completes `token` with the state name of node's next boot-up (boot_up), heartbeat in `state`, or "
          "any heartbeat; cancel() the returned waiter when no longer wanted (C++ canopen::NmtEventWait).");
}

static void bind_heartbeat(py::module_& m) {
    // ---- heartbeat --------------------------------------------------------------
    py::class_<HeartbeatConsumer, std::shared_ptr<HeartbeatConsumer>>(m, "HeartbeatConsumer",
        "Per-node heartbeat supervision: started / lost / back / reset / state events.")
        .def(py::init([](BusPtr bus, ClockPtr clock) {
                 not_none(bus, "bus");
                 clock = clock_or_real(clock);
                 return make_service<HeartbeatConsumer>(std::pair(bus, clock), *bus, *clock);
             }), py::arg("bus"), py::arg("clock") = nullptr)
        .def("monitor", [](HeartbeatConsumer& b, int node, double timeout) {
                 check_node(node, false);
                 auto t = duration_arg(timeout, "timeout");
                 if (t.count() <= 0) throw InvalidArgument("timeout: a heartbeat timeout must be > 0 s");
                 b.monitor(static_cast<std::uint8_t>(node), t);
             }, py::arg("node"), py::arg("timeout"))
        .def("forget", [](HeartbeatConsumer& b, int node) { check_node(node, false); b.forget(static_cast<std::uint8_t>(node)); })
        .def("health", [](HeartbeatConsumer& b, int node) { check_node(node, false); return b.health(static_cast<std::uint8_t>(node)); })
        .def("process", [](HeartbeatConsumer& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.process(now ? *now : b.clock().now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](HeartbeatConsumer& b) { b.start(); })
        .def("stop", [](HeartbeatConsumer& b) { py::gil_scoped_release nogil; b.stop(); })
        .def("set_callback", [](HeartbeatConsumer& b, py::object cb) {
                 if (cb.is_none()) { b.on_event = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.on_event = [call](std::uint8_t n, HeartbeatEvent e, NodeState s) {
                     call(n, std::string(to_string(e)), std::string(to_string(s)));
                 };
             }, py::arg("callback"), "callback(node, event, state); events: started, lost, back, reset, state-changed, unknown-state.")
        .def_property_readonly("ignored_frames", [](HeartbeatConsumer& b) { return b.ignored_frames(); });

    py::class_<HeartbeatProducer, std::shared_ptr<HeartbeatProducer>>(m, "HeartbeatProducer")
        .def(py::init([](BusPtr bus, int node, double period, py::object state, ClockPtr clock) {
                 not_none(bus, "bus");
                 check_node(node, false);
                 const auto period_ns = duration_arg(period, "period");
                 clock = clock_or_real(clock);
                 std::function<NodeState()> fn;
                 if (py::isinstance<py::str>(state)) {
                     auto st = node_state_of(state.cast<std::string>());
                     fn = [st] { return st; };
                 } else {
                     // Released from a thread without the GIL: take it for the decref.
                     std::shared_ptr<py::object> holder(new py::object(state), [](py::object* o) {
                         if (!Py_IsInitialized()) return;
                         py::gil_scoped_acquire gil;
                         delete o;
                     });
                     fn = [holder] {
                         py::gil_scoped_acquire gil;
                         return node_state_of((*holder)().cast<std::string>());
                     };
                 }
                 return make_service<HeartbeatProducer>(std::pair(bus, clock), *bus, *clock, static_cast<std::uint8_t>(node),
                                                        period_ns, fn);
                 
             }), py::arg("bus"), py::arg("node"), py::arg("period"), py::arg("state") = "OPERATIONAL",
             py::arg("clock") = nullptr)
        .def("send_boot_up", [](HeartbeatProducer& b) { py::gil_scoped_release nogil; b.send_boot_up(); })
        .def("process", [](HeartbeatProducer& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.process(now ? *now : b.clock().now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](HeartbeatProducer& b) { b.start(); })
        .def("stop", [](HeartbeatProducer& b) { py::gil_scoped_release nogil; b.stop(); })
        .def_property_readonly("send_failures", [](HeartbeatProducer& b) { return b.send_failures(); },
                               "heartbeats the bus refused (closed, full, link down) while started")
        .def_property_readonly("sent", [](HeartbeatProducer& b) { return b.sent(); });
}

static void bind_emcy(py::module_& m) {
    // ---- EMCY -------------------------------------------------------------------
    py::class_<EmcyConsumer, std::shared_ptr<EmcyConsumer>>(m, "EmcyConsumer",
        "Collects EMCY messages: bounded history and active codes per node.")
        .def(py::init([](BusPtr bus, std::size_t history) {
                 not_none(bus, "bus");
                 return make_service<EmcyConsumer>(bus, *bus, history);
             }), py::arg("bus"), py::arg("history") = 32)
        .def("history", [](EmcyConsumer& b, int node) {
                 check_node(node, false);
                 py::list l;
                 for (auto& e : b.history(static_cast<std::uint8_t>(node))) l.append(py::cast(e));
                 return l;
             }, py::arg("node"))
        .def("active", [](EmcyConsumer& b, int node) { check_node(node, false); return b.active(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("clear", [](EmcyConsumer& b, int node) { check_node(node, false); b.clear(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("wait", [](EmcyConsumer& b, int node, const py::object& t) -> py::object {
                 check_node(node, true);
                 auto to = timeout_of(t);
                 std::optional<EmcyMessage> r;
                 r = blocking_call([&] { return b.wait(static_cast<std::uint8_t>(node), to); });
                 if (!r) return py::none();
                 return py::cast(*r);
             }, py::arg("node") = 0, py::arg("timeout") = 1.0)
        .def("set_callback", [](EmcyConsumer& b, py::object cb) {
                 if (cb.is_none()) { b.on_emcy = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.on_emcy = [call](const EmcyMessage& e) { call(e); };
             }, py::arg("callback"))
        .def_property_readonly("received", [](EmcyConsumer& b) { return b.received(); })
        .def_property_readonly("ignored_frames", [](EmcyConsumer& b) { return b.ignored_frames(); });

    py::class_<EmcyProducer, std::shared_ptr<EmcyProducer>>(m, "EmcyProducer")
        .def(py::init([](BusPtr bus, int node, std::uint16_t inhibit, std::size_t queue, ClockPtr clock) {
                 not_none(bus, "bus");
                 check_node(node, false);
                 clock = clock_or_real(clock);
                 return make_service<EmcyProducer>(std::pair(bus, clock), *bus, *clock, static_cast<std::uint8_t>(node),
                                                   inhibit, queue);
             }), py::arg("bus"), py::arg("node"), py::arg("inhibit_100us") = 0, py::arg("queue_limit") = 16,
             py::arg("clock") = nullptr)
        .def("report", [](EmcyProducer& b, std::uint16_t code, std::uint8_t reg, const py::bytes& data) {
                 auto d = from_bytes(data);
                 if (d.size() > 5) throw InvalidArgument("EMCY manufacturer data: at most 5 bytes");
                 std::array<std::uint8_t, 5> msef{};
                 std::copy(d.begin(), d.end(), msef.begin());
                 py::gil_scoped_release nogil;
                 return b.report(code, reg, msef);
             }, py::arg("code"), py::arg("register") = 0, py::arg("data") = py::bytes())
        .def("process", [](EmcyProducer& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.process(now ? *now : b.clock().now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](EmcyProducer& b) { b.start(); })
        .def("stop", [](EmcyProducer& b) { py::gil_scoped_release nogil; b.stop(); })
        .def_property_readonly("pending", [](EmcyProducer& b) { return b.pending(); })
        .def_property_readonly("sent", [](EmcyProducer& b) { return b.sent(); })
        .def_property_readonly("dropped", [](EmcyProducer& b) { return b.dropped(); });
}

static void bind_sync(py::module_& m) {
    // ---- SYNC -------------------------------------------------------------------
    py::class_<SyncProducer, std::shared_ptr<SyncProducer>>(m, "SyncProducer",
        "SYNC on a C++ thread; jitter() reports the period error statistics.")
        .def(py::init([](BusPtr bus, double period, int overflow, std::uint32_t cob_id) {
                 not_none(bus, "bus");
                 const auto period_ns = duration_arg(period, "period");
                 if (period_ns.count() <= 0) throw InvalidArgument("period: a SYNC period must be > 0 s");
                 // The core refuses an overflow other than 0 or 2-240.
                 return make_service<SyncProducer>(bus, *bus, period_ns, saturate<std::uint8_t>(overflow), cob_id);
             }), py::arg("bus"), py::arg("period"), py::arg("counter_overflow") = 0, py::arg("cob_id") = kSyncCobId)
        .def("start", [](SyncProducer& b, bool realtime) { b.start(realtime); }, py::arg("realtime") = false,
             "realtime=True asks for SCHED_FIFO; see realtime_granted.")
        .def("stop", [](SyncProducer& b) { py::gil_scoped_release nogil; b.stop(); })
        .def_property_readonly("running", [](SyncProducer& b) { return b.running(); })
        .def_property_readonly("realtime_granted", [](SyncProducer& b) { return b.realtime_granted(); })
        .def_property_readonly("sent", [](SyncProducer& b) { return b.sent(); })
        .def("jitter", [](SyncProducer& b) { return b.jitter(); })
        .def("reset_stats", [](SyncProducer& b) { b.reset_stats(); });
}

static void bind_pdo(py::module_& m) {
    // ---- PDO ----------------------------------------------------------------------
    py::class_<PdoLayout>(m, "PdoLayout", "A compiled PDO mapping: bit-exact pack/unpack (CiA 301, little-endian).")
        .def(py::init([](const py::iterable& entries) {
                 auto v = entries_from(entries);
                 return PdoLayout(v);
             }), py::arg("entries"))
        .def_property_readonly("entries", [](const PdoLayout& l) { return entries_to(l.entries()); })
        .def_property_readonly("total_bits", &PdoLayout::total_bits)
        .def_property_readonly("length", &PdoLayout::byte_length)
        .def("offset", [](const PdoLayout& l, std::size_t i) {
                 if (i >= l.size()) throw py::index_error("entry index");
                 return l.offset(i);
             })
        .def("pack", [](const PdoLayout& l, const std::vector<std::int64_t>& values) {
                 // The layout keeps each value's low bits: a negative one packs as its two's complement.
                 const std::vector<std::uint64_t> v(values.begin(), values.end());
                 return to_bytes(l.pack(v));  // the core refuses a wrong count
             }, py::arg("values"), "Values are ints (negative ones in two's complement of their width).")
        .def("pack_unsigned", [](const PdoLayout& l, const std::vector<std::uint64_t>& values) {
                 return to_bytes(l.pack(values));
             }, py::arg("values"))
        .def("unpack", [](const PdoLayout& l, const py::bytes& data) {
                 auto d = from_bytes(data);
                 std::uint64_t v[PdoLayout::kMaxEntries];
                 if (!l.unpack(d.data(), d.size(), v))
                     throw ProtocolError("PDO unpack: " + std::to_string(d.size()) + " bytes, mapping needs " +
                                         std::to_string(l.byte_length()), d);
                 py::list out;
                 for (std::size_t i = 0; i < l.size(); ++i) {
                     if (l.entry(i).is_signed) out.append(py::int_(l.to_signed(i, v[i])));
                     else out.append(py::int_(v[i]));
                 }
                 return out;
             }, py::arg("data"), "Signed entries (4th tuple item True) are sign-extended.");

    py::class_<PdoReceiver, std::shared_ptr<PdoReceiver>>(m, "PdoReceiver",
        "Receives a device's TPDO on the bus and keeps the latest values.")
        .def(py::init([](BusPtr bus, std::uint32_t cob_id, const py::iterable& entries) {
                 not_none(bus, "bus");
                 return make_service<PdoReceiver>(bus, *bus, cob_id, entries_from(entries));
             }), py::arg("bus"), py::arg("cob_id"), py::arg("entries"))
        .def_property_readonly("values", [](PdoReceiver& b) { return b.values(); })
        .def("value", [](PdoReceiver& b, std::uint16_t i, std::uint8_t s) { return b.value(i, s); },
             py::arg("index"), py::arg("subindex") = 0)
        .def_property_readonly("received", [](PdoReceiver& b) { return b.received(); })
        .def_property_readonly("short_frames", [](PdoReceiver& b) { return b.short_frames(); })
        .def("wait_newer", [](PdoReceiver& b, std::uint64_t after, const py::object& t) {
                 auto to = timeout_of(t);
                 return blocking_call([&] { return b.wait_newer(after, to); });
             }, py::arg("after"), py::arg("timeout") = 1.0)
        .def("request", [](PdoReceiver& b) { py::gil_scoped_release nogil; b.request(); })
        .def("set_callback", [](PdoReceiver& b, py::object cb) {
                 if (cb.is_none()) { b.on_receive = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.on_receive = [call](const std::vector<std::uint64_t>& v, Nanos ts) { call(v, ts); };
             }, py::arg("callback"), "callback(values, timestamp_ns) on the bus thread.");

    py::class_<PdoSender, std::shared_ptr<PdoSender>>(m, "PdoSender")
        .def(py::init([](BusPtr bus, std::uint32_t cob_id, const py::iterable& entries) {
                 not_none(bus, "bus");
                 return make_service<PdoSender>(bus, *bus, cob_id, entries_from(entries));
             }), py::arg("bus"), py::arg("cob_id"), py::arg("entries"))
        .def("send", [](PdoSender& b, const std::vector<std::int64_t>& values, const py::object& t) {
                 std::vector<std::uint64_t> v(values.begin(), values.end());
                 auto to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 b.send(v, to);
             }, py::arg("values"), py::arg("timeout") = 1.0);

    m.def("pdo_write_config",
          [](const py::object& sdo, int node, bool tpdo, unsigned number, std::optional<std::uint32_t> cob_id,
             bool enabled, std::optional<int> ttype, std::optional<int> inhibit, std::optional<int> timer,
             std::optional<int> sync_start, std::optional<py::iterable> mapping, const py::object& procedure) {
              check_node(node, false);
              auto box = make_sdo(sdo, node);
              PdoConfig c;
              c.tpdo = tpdo;
              c.number = number;
              c.cob_id = cob_id;
              c.enabled = enabled;
              auto u8 = [](std::optional<int> v, const char* what) -> std::optional<std::uint8_t> {
                  if (!v) return std::nullopt;
                  if (*v < 0 || *v > 255) throw InvalidArgument(std::string(what) + " must be 0-255");
                  return static_cast<std::uint8_t>(*v);
              };
              auto u16 = [](std::optional<int> v, const char* what) -> std::optional<std::uint16_t> {
                  if (!v) return std::nullopt;
                  if (*v < 0 || *v > 65535) throw InvalidArgument(std::string(what) + " must be 0-65535");
                  return static_cast<std::uint16_t>(*v);
              };
              c.transmission_type = u8(ttype, "transmission type");
              c.inhibit_100us = u16(inhibit, "inhibit time");
              c.event_timer_ms = u16(timer, "event timer");
              c.sync_start = u8(sync_start, "sync start");
              if (mapping) c.mapping = entries_from(*mapping);
              PdoProcedure p;
              if (py::isinstance<PdoProcedure>(procedure)) {
                  p = procedure.cast<PdoProcedure>();
              } else if (auto named = pdo_procedure_from_name(procedure.cast<std::string>())) {
                  p = *named;
              } else {
                  throw InvalidArgument("procedure must be 'cia301' or 'direct'");
              }
              py::gil_scoped_release nogil;
              write_pdo(*box.access, static_cast<std::uint8_t>(node), c, p);
          },
          py::arg("sdo"), py::arg("node"), py::arg("tpdo"), py::arg("number"), py::arg("cob_id") = py::none(),
          py::arg("enabled") = true, py::arg("transmission_type") = py::none(), py::arg("inhibit_100us") = py::none(),
          py::arg("event_timer_ms") = py::none(), py::arg("sync_start") = py::none(), py::arg("mapping") = py::none(),
          py::arg("procedure") = "cia301", "procedure: a PdoProcedure or its name ('cia301', 'direct').");
    m.def("pdo_read_config", [](const py::object& sdo, int node, bool tpdo, unsigned number) {
              check_node(node, false);
              auto box = make_sdo(sdo, node);
              PdoConfig c;
              {
                  py::gil_scoped_release nogil;
                  c = read_pdo(*box.access, static_cast<std::uint8_t>(node), tpdo, number);
              }
              return c;
          }, py::arg("sdo"), py::arg("node"), py::arg("tpdo"), py::arg("number"));
}

static void bind_cia402(py::module_& m) {
    // ---- CiA 402 ------------------------------------------------------------------
    m.def("cia402_decode_statusword", [](std::uint16_t sw) { return std::string(to_string(decode_statusword(sw))); },
          py::arg("statusword"), "State name; 'UNKNOWN' for patterns outside the table.");
    m.def("cia402_next_step", [](const std::string& from, const std::string& to) -> py::object {
              auto s = next_step(cia402_state_of(from), cia402_state_of(to));
              if (!s) return py::none();
              return py::make_tuple(s->controlword, s->transition);
          }, py::arg("from_state"), py::arg("to_state"));

    py::class_<Cia402Host, std::shared_ptr<Cia402Host>>(m, "Cia402Host",
        "CiA 402 power state machine and PP/PV/HM handshakes, driven from the host.")
        .def(py::init([](const py::object& sdo, int node, double timeout, double poll) {
                 check_node(node, false);
                 auto box = make_sdo(sdo, node);
                 SdoAccess& access = *box.access;  // owned by box, which the host keeps
                 Cia402HostOptions o;
                 o.timeout = finite_forever(duration_arg(timeout, "timeout", Forever::Allowed));
                 o.sdo_poll = duration_arg(poll, "poll");
                 return make_service<Cia402Host>(std::move(box), access, static_cast<std::uint8_t>(node), o);
             }), py::arg("sdo"), py::arg("node"), py::arg("timeout") = 2.0, py::arg("poll") = 0.005)
        .def("use_statusword_pdo", [](Cia402Host& b, PdoReceiver* rx) { b.use_statusword_pdo(rx); },
             py::arg("receiver"), py::keep_alive<1, 2>(),
             "Wait on this TPDO receiver's statusword (0x6041 must be mapped); None = poll over SDO.")
        .def_property_readonly("statusword", [](Cia402Host& b) { return blocking_call([&] { return b.read_statusword(); }); })
        .def_property_readonly("state", [](Cia402Host& b) {
                 Cia402State s;
                 s = blocking_call([&] { return b.state(); });
                 return std::string(to_string(s));
             })
        .def("write_controlword", [](Cia402Host& b, std::uint16_t c) { blocking_call([&] { b.write_controlword(c); }); })
        .def("go_to", [](Cia402Host& b, const std::string& s) {
                 auto t = cia402_state_of(s);
                 blocking_call([&] { b.go_to(t); });
             }, py::arg("state"))
        .def("fault_reset", [](Cia402Host& b) { blocking_call([&] { b.fault_reset(); }); })
        .def("quick_stop", [](Cia402Host& b) { blocking_call([&] { b.quick_stop(); }); })
        .def("wait_statusword", [](Cia402Host& b, std::uint16_t mask, std::uint16_t value, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 return blocking_call([&] { return b.wait_statusword(mask, value, to); });
             }, py::arg("mask"), py::arg("value"), py::arg("timeout") = py::none())
        .def("set_mode", [](Cia402Host& b, int mode) {
                 blocking_call([&] { b.set_mode(static_cast<OpMode>(mode)); });
             }, py::arg("mode"))
        .def_property_readonly("mode", [](Cia402Host& b) { return blocking_call([&] { return static_cast<int>(b.mode()); }); })
        .def("move_to", [](Cia402Host& b, std::int32_t target, bool relative, bool immediate) {
                 blocking_call([&] { b.move_to(target, relative, immediate); });
             }, py::arg("target"), py::arg("relative") = false, py::arg("immediate") = true)
        .def("wait_target_reached", [](Cia402Host& b, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 blocking_call([&] { b.wait_target_reached(to); });
             }, py::arg("timeout") = py::none())
        .def("set_velocity", [](Cia402Host& b, std::int32_t v) { blocking_call([&] { b.set_velocity(v); }); })
        .def("home", [](Cia402Host& b, std::optional<int> method, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 std::optional<std::int8_t> mth;
                 if (method) mth = static_cast<std::int8_t>(*method);
                 blocking_call([&] { b.home(mth, to); });
             }, py::arg("method") = py::none(), py::arg("timeout") = py::none());

    py::class_<Cia402Device, std::shared_ptr<Cia402Device>>(m, "Cia402Device",
        "Device-side CiA 402 state machine for simulators.")
        .def(py::init([] { return std::make_shared<Cia402Device>(); }))
        .def_property_readonly("state", [](const Cia402Device& d) { return std::string(to_string(d.state())); })
        .def_property_readonly("statusword", &Cia402Device::statusword)
        .def_property_readonly("controlword", &Cia402Device::controlword)
        .def("on_controlword", &Cia402Device::on_controlword, py::arg("controlword"))
        .def("set_mode", &Cia402Device::set_mode, py::arg("mode"), "0 or the SDO abort code (0x06090030).")
        .def_property_readonly("mode", &Cia402Device::mode)
        .def("set_supported_modes", &Cia402Device::set_supported_modes)
        .def("set_abort_connection_option", &Cia402Device::set_abort_connection_option)
        .def("set_quick_stop_option", &Cia402Device::set_quick_stop_option)
        .def("fault", &Cia402Device::fault, py::arg("error_code"))
        .def("fault_reaction_done", &Cia402Device::fault_reaction_done)
        .def("loss_of_master", &Cia402Device::loss_of_master)
        .def("motion_stopped", &Cia402Device::motion_stopped)
        .def("set_status_bits", &Cia402Device::set_status_bits, py::arg("mask"), py::arg("value"))
        .def_property_readonly("last_error_code", &Cia402Device::last_error_code)
        .def_property_readonly("drive_enabled", &Cia402Device::drive_enabled);
}

static void bind_pdo_service(py::module_& m) {
    // ---- PDO engine on a LocalNode -----------------------------------------------------
    py::class_<PdoService, std::shared_ptr<PdoService>>(m, "PdoService",
        "The PDO engine of a LocalNode: 0x1400-0x1BFF in its dictionary, TPDOs/RPDOs on its bus.")
        .def(py::init([](LocalNode& node, unsigned rpdos, unsigned tpdos, unsigned max_mapped, bool strict,
                         std::uint32_t sync_window_us) {
                 PdoServiceOptions o;
                 o.rpdo_count = rpdos;
                 o.tpdo_count = tpdos;
                 o.max_mapped = max_mapped;
                 o.strict = strict;
                 o.sync_window_us = sync_window_us;
                 py::gil_scoped_release nogil;
                 return PdoService::attach(node, o);
             }), py::arg("node"), py::arg("rpdos") = 4, py::arg("tpdos") = 4, py::arg("max_mapped") = 8,
             py::arg("strict") = true, py::arg("sync_window_us") = 0, py::keep_alive<1, 2>())
        // The engine's lock is held while a TPDO reads its objects, whose read hooks may
        // take the GIL: never wait for that lock holding the GIL.
        .def("mapping", [](PdoService& s, bool tpdo, unsigned n) {
                 std::vector<PdoMapEntry> v;
                 {
                     py::gil_scoped_release nogil;
                     v = s.engine().mapping(tpdo, n);
                 }
                 return entries_to(v);
             },
             py::arg("tpdo"), py::arg("number"))
        .def("cob_id", [](PdoService& s, bool tpdo, unsigned n) {
                 py::gil_scoped_release nogil;
                 return s.engine().cob_id(tpdo, n);
             },
             py::arg("tpdo"), py::arg("number"))
        .def("trigger_tpdo", [](PdoService& s, unsigned n) { py::gil_scoped_release nogil; s.engine().trigger_tpdo(n); })
        .def("notify_change", [](PdoService& s, std::uint16_t i, std::uint8_t sub) {
                 py::gil_scoped_release nogil;
                 s.engine().notify_change(i, sub);
             }, py::arg("index"), py::arg("subindex") = 0)
        .def("set_rpdo_timeout_callback", [](PdoService& s, py::object cb) {
                 if (cb.is_none()) { s.engine().on_rpdo_timeout = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 s.engine().on_rpdo_timeout = [call](unsigned n) { call(n); };
             }, py::arg("callback"), "callback(rpdo_number) when an RPDO's event timer expires (P11).")
        .def_property_readonly("counters", [](PdoService& s) {
            py::gil_scoped_release nogil;
            return s.engine().counters();
        });

    py::class_<HeartbeatService, std::shared_ptr<HeartbeatService>>(m, "HeartbeatService",
        "Heartbeat producer (0x1017) and consumer (0x1016) of a LocalNode; EMCY 0x8130 and 0x1029 on loss.")
        .def(py::init([](LocalNode& node, unsigned entries, std::uint16_t producer_ms) {
                 HeartbeatServiceOptions o;
                 o.consumer_entries = entries;
                 o.producer_ms = producer_ms;
                 py::gil_scoped_release nogil;
                 return HeartbeatService::attach(node, o);
             }), py::arg("node"), py::arg("consumer_entries") = 4, py::arg("producer_ms") = 0,
             py::keep_alive<1, 2>())
        .def("health", [](HeartbeatService& s, int node) { check_node(node, false); return s.health(static_cast<std::uint8_t>(node)); })
        .def_property_readonly("heartbeats_sent", &HeartbeatService::heartbeats_sent)
        .def("set_lost_callback", [](HeartbeatService& s, py::object cb) {
                 if (cb.is_none()) { s.on_lost = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 s.on_lost = [call](std::uint8_t n) { call(n); };
             }, py::arg("callback"), "callback(node) when a consumed heartbeat is lost (e.g. Cia402Device.loss_of_master).");
}

static void bind_scanner(py::module_& m) {
    // ---- scanner ------------------------------------------------------------------
    m.def("scan_network", [](BusPtr bus, int first, int last, double sdo_timeout, double listen, bool probe_sdo,
                             bool identity) {
              not_none(bus, "bus");
              ScanOptions o;  // the core refuses a range outside 1-127
              o.first = saturate<std::uint8_t>(first);
              o.last = saturate<std::uint8_t>(last);
              o.sdo_timeout = duration_arg(sdo_timeout, "sdo_timeout");
              o.listen = duration_arg(listen, "listen");
              o.probe_sdo = probe_sdo;
              o.read_identity = identity;
              std::vector<ScanResult> res;
              res = blocking_call([&] { return scan_network(*bus, o); });
              return res;
          }, py::arg("bus"), py::arg("first") = 1, py::arg("last") = 127, py::arg("sdo_timeout") = 0.2,
          py::arg("listen") = 0.0, py::arg("probe_sdo") = true, py::arg("identity") = true);

    // A PollSource capturing TPDOs (motorbus.Poller mode "capture"); the drive kind configures them.
    py::class_<PdoCaptureSource, poll::Source, std::shared_ptr<PdoCaptureSource>>(
        m, "PdoCaptureSource", "A PollSource taking the latest values of TPDOs (columns: arrival ns, values).")
        .def(py::init([](BusPtr bus, int node, const std::vector<std::pair<std::uint32_t, py::iterable>>& tpdos,
                         const std::vector<std::pair<std::size_t, std::size_t>>& columns, const py::object& max_age) {
                 not_none(bus, "bus");
                 std::vector<CapturedPdo> pdos;
                 for (const auto& [cob, entries] : tpdos) pdos.push_back({cob, entries_from(entries)});
                 const Nanos age = duration_arg(max_age, "max_age").count();
                 return make_service<PdoCaptureSource>(bus, *bus, static_cast<std::uint8_t>(node), std::move(pdos),
                                                       columns, age);
             }),
             py::arg("bus"), py::arg("node"), py::arg("tpdos"), py::arg("columns"), py::arg("max_age"),
             "tpdos: [(cob_id, [(index, sub, bits, signed)])]; columns: [(tpdo i, entry j)] in row order; "
             "max_age (s): older data counts as stale.")
        .def_property_readonly("received", &PdoCaptureSource::received)
        .def_property_readonly("short_frames", &PdoCaptureSource::short_frames)
        .def("close", &PdoCaptureSource::close, py::call_guard<py::gil_scoped_release>(), "Stops listening.");
}

void bind_canopen_services(py::module_& m) {
    bind_records(m);
    bind_codecs(m);
    bind_nmt(m);
    bind_heartbeat(m);
    bind_emcy(m);
    bind_sync(m);
    bind_pdo(m);
    bind_cia402(m);
    bind_pdo_service(m);
    bind_scanner(m);
}
