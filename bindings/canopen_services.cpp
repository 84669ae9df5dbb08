// Bindings for the CANopen services: NMT, heartbeat, EMCY, SYNC, TIME, PDO,
// CiA 402 and the network scanner.  Thin: conversion, GIL release, lifetimes.
//
// Objects that subscribe to a bus keep the bus (and clock) alive and are
// destroyed with the GIL released, because unsubscribing waits for a callback
// that may itself be waiting for the GIL.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "motorbus/can/bus.hpp"
#include "motorbus/canopen/ds402.hpp"
#include "motorbus/canopen/emcy.hpp"
#include "motorbus/canopen/heartbeat.hpp"
#include "motorbus/canopen/heartbeat_service.hpp"
#include "motorbus/canopen/nmt.hpp"
#include "motorbus/canopen/pdo.hpp"
#include "motorbus/canopen/pdo_engine.hpp"
#include "motorbus/canopen/pdo_service.hpp"
#include "motorbus/canopen/sdo_client.hpp"
#include "motorbus/canopen/scanner.hpp"
#include "motorbus/canopen/services_sdo_adapter.hpp"
#include "motorbus/canopen/sync.hpp"
#include "motorbus/canopen/time.hpp"
#include "motorbus/errors.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::py_helpers::PyCallable;
using motorbus::py_helpers::seconds_to_ns;

namespace {

using BusPtr = std::shared_ptr<can::Bus>;
using ClockPtr = std::shared_ptr<Clock>;

template <class T, class... A>
std::shared_ptr<T> make_nogil(A&&... args) {
    return std::shared_ptr<T>(new T(std::forward<A>(args)...), [](T* p) {
        if (PyGILState_Check()) {
            py::gil_scoped_release nogil;
            delete p;
        } else {
            delete p;
        }
    });
}

ClockPtr clock_or_real(const ClockPtr& c) { return c ? c : std::make_shared<RealClock>(); }

std::chrono::nanoseconds timeout_of(const py::object& t) {
    auto ns = seconds_to_ns(t);
    return ns.count() < 0 ? std::chrono::hours(24 * 365) : ns;
}

py::bytes to_bytes(std::span<const std::uint8_t> b) {
    return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
}

std::vector<std::uint8_t> from_bytes(const py::bytes& b) {
    std::string s = b;
    return {s.begin(), s.end()};
}

// Every wrapper keeps what the C++ object refers to alive.
struct NmtMasterBox {
    BusPtr bus;
    std::shared_ptr<NmtMaster> obj;
};
struct HbConsumerBox {
    BusPtr bus;
    ClockPtr clock;
    std::shared_ptr<HeartbeatConsumer> obj;
};
struct HbProducerBox {
    BusPtr bus;
    ClockPtr clock;
    std::shared_ptr<HeartbeatProducer> obj;
};
struct EmcyConsumerBox {
    BusPtr bus;
    std::shared_ptr<EmcyConsumer> obj;
};
struct EmcyProducerBox {
    BusPtr bus;
    ClockPtr clock;
    std::shared_ptr<EmcyProducer> obj;
};
struct SyncProducerBox {
    BusPtr bus;
    std::shared_ptr<SyncProducer> obj;
};
struct PdoReceiverBox {
    BusPtr bus;
    std::shared_ptr<PdoReceiver> obj;
};
struct PdoSenderBox {
    BusPtr bus;
    std::shared_ptr<PdoSender> obj;
};

// SdoAccess over a Python object with upload(index, sub) -> bytes and
// download(index, sub, data): lets any SDO client (canopen-sdo's binding, a
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
        // canopen-sdo's client: called directly in C++, no GIL round trip.
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

struct Ds402HostBox {
    SdoBox sdo;
    std::shared_ptr<Ds402Host> obj;
    std::shared_ptr<PdoReceiverBox> sw_pdo;
};

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

py::dict emcy_dict(const EmcyMessage& m) {
    py::dict d;
    d["node"] = m.node_id;
    d["code"] = m.code;
    d["register"] = m.error_register;
    d["data"] = to_bytes(m.manufacturer);
    d["short"] = m.short_frame;
    d["timestamp_ns"] = m.timestamp_ns;
    d["text"] = emcy_code_text(m.code);
    return d;
}

py::dict health_dict(const NodeHealth& h) {
    py::dict d;
    d["node"] = h.node_id;
    d["state"] = to_string(h.state);
    d["raw_state"] = h.raw_state;
    d["alive"] = h.alive;
    d["lost"] = h.lost;
    d["last_seen_ns"] = h.last_seen;
    d["heartbeats"] = h.heartbeats;
    d["boot_ups"] = h.boot_ups;
    d["timeouts"] = h.timeouts;
    return d;
}

NodeState node_state_from_name(const std::string& s) {
    for (auto st : {NodeState::Initialising, NodeState::Stopped, NodeState::Operational,
                    NodeState::PreOperational, NodeState::Unknown})
        if (s == to_string(st)) return st;
    throw InvalidArgument("NMT state: expected INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL; got " + s);
}

Ds402State ds402_from_name(const std::string& s) {
    for (int i = 0; i <= static_cast<int>(Ds402State::Unknown); ++i)
        if (s == to_string(static_cast<Ds402State>(i))) return static_cast<Ds402State>(i);
    throw InvalidArgument("CiA 402 state name not known: " + s);
}

void check_node(int n, bool allow_zero) {
    if (n < (allow_zero ? 0 : 1) || n > 127)
        throw InvalidArgument("node id " + std::to_string(n) + (allow_zero ? " is outside 0-127" : " is outside 1-127"));
}

}  // namespace

void bind_canopen_services(py::module_& m) {
    // ---- pure codecs --------------------------------------------------------
    m.def("nmt_encode", [](int cs, int node) {
              if (!is_known_nmt_command(static_cast<std::uint8_t>(cs)) || cs < 0 || cs > 255)
                  throw InvalidArgument("NMT command specifier must be 0x01, 0x02, 0x80, 0x81 or 0x82");
              check_node(node, true);
              return encode_nmt(static_cast<NmtCommand>(cs), static_cast<std::uint8_t>(node));
          }, py::arg("command"), py::arg("node"));
    m.def("nmt_decode", [](const can::Frame& f) -> py::object {
              auto d = decode_nmt(f);
              if (!d) return py::none();
              return py::make_tuple(static_cast<int>(d->command), d->node_id);
          }, py::arg("frame"), "(command, node) or None for anything that is not a valid NMT frame.");
    m.def("heartbeat_encode", [](int node, const std::string& state) {
              check_node(node, false);
              return encode_heartbeat(static_cast<std::uint8_t>(node), node_state_from_name(state));
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
              return emcy_dict(*d);
          }, py::arg("frame"));
    m.def("emcy_code_text", &emcy_code_text, py::arg("code"));
    m.def("sync_encode", [](std::optional<int> counter, std::uint32_t cob_id) {
              if (counter && (*counter < 1 || *counter > 240)) throw InvalidArgument("SYNC counter must be 1-240");
              return encode_sync(counter ? std::optional<std::uint8_t>(static_cast<std::uint8_t>(*counter))
                                         : std::nullopt,
                                 cob_id);
          }, py::arg("counter") = py::none(), py::arg("cob_id") = kSyncCobId);
    m.def("time_encode", [](std::int64_t unix_ms) { return encode_time(TimeOfDay::from_unix_ms(unix_ms)); },
          py::arg("unix_ms"));
    m.def("time_decode", [](const can::Frame& f) -> py::object {
              auto t = decode_time(f);
              if (!t) return py::none();
              return py::int_(t->to_unix_ms());
          }, py::arg("frame"), "Unix time in ms, or None.");

    // ---- NMT master -----------------------------------------------------------
    py::class_<NmtMasterBox, std::shared_ptr<NmtMasterBox>>(m, "NmtMaster",
        "Sends NMT commands and tracks node states from heartbeats and boot-ups.")
        .def(py::init([](BusPtr bus, std::optional<int> own) {
                 if (own) check_node(*own, false);
                 auto b = std::make_shared<NmtMasterBox>();
                 b->bus = bus;
                 b->obj = make_nogil<NmtMaster>(*bus, own ? std::optional<std::uint8_t>(static_cast<std::uint8_t>(*own))
                                                          : std::nullopt);
                 return b;
             }), py::arg("bus"), py::arg("own_node_id") = py::none())
        .def("send", [](NmtMasterBox& b, int cs, int node) {
                 if (cs < 0 || cs > 255 || !is_known_nmt_command(static_cast<std::uint8_t>(cs)))
                     throw InvalidArgument("NMT command specifier must be 0x01, 0x02, 0x80, 0x81 or 0x82");
                 check_node(node, true);
                 py::gil_scoped_release nogil;
                 b.obj->send(static_cast<NmtCommand>(cs), static_cast<std::uint8_t>(node));
             }, py::arg("command"), py::arg("node"))
        .def("state", [](NmtMasterBox& b, int node) { check_node(node, false); return to_string(b.obj->state(static_cast<std::uint8_t>(node))); }, py::arg("node"))
        .def("raw_state", [](NmtMasterBox& b, int node) { check_node(node, false); return b.obj->raw_state(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("wait_for_state", [](NmtMasterBox& b, int node, const std::string& st, const py::object& t) {
                 check_node(node, false);
                 auto want = node_state_from_name(st);
                 auto to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 return b.obj->wait_for_state(static_cast<std::uint8_t>(node), want, to);
             }, py::arg("node"), py::arg("state"), py::arg("timeout") = 1.0)
        .def("wait_for_boot", [](NmtMasterBox& b, int node, const py::object& t) {
                 check_node(node, false);
                 auto to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 return b.obj->wait_for_boot(static_cast<std::uint8_t>(node), to);
             }, py::arg("node"), py::arg("timeout") = 1.0)
        .def("set_callback", [](NmtMasterBox& b, py::object cb) {
                 if (cb.is_none()) { b.obj->on_state_change = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.obj->on_state_change = [call](std::uint8_t n, NodeState a, NodeState c) {
                     call(n, std::string(to_string(a)), std::string(to_string(c)));
                 };
             }, py::arg("callback"), "callback(node, old_state, new_state) on the bus thread.")
        .def_property_readonly("foreign_commands_ignored", [](NmtMasterBox& b) { return b.obj->foreign_commands_ignored(); });

    // ---- heartbeat --------------------------------------------------------------
    py::class_<HbConsumerBox, std::shared_ptr<HbConsumerBox>>(m, "HeartbeatConsumer",
        "Per-node heartbeat supervision: started / lost / back / reset / state events.")
        .def(py::init([](BusPtr bus, ClockPtr clock) {
                 auto b = std::make_shared<HbConsumerBox>();
                 b->bus = bus;
                 b->clock = clock_or_real(clock);
                 b->obj = make_nogil<HeartbeatConsumer>(*bus, *b->clock);
                 return b;
             }), py::arg("bus"), py::arg("clock") = nullptr)
        .def("monitor", [](HbConsumerBox& b, int node, double timeout) {
                 check_node(node, false);
                 if (!(timeout > 0)) throw InvalidArgument("heartbeat timeout must be > 0 s");
                 b.obj->monitor(static_cast<std::uint8_t>(node), std::chrono::nanoseconds(static_cast<std::int64_t>(timeout * 1e9)));
             }, py::arg("node"), py::arg("timeout"))
        .def("forget", [](HbConsumerBox& b, int node) { check_node(node, false); b.obj->forget(static_cast<std::uint8_t>(node)); })
        .def("health", [](HbConsumerBox& b, int node) { check_node(node, false); return health_dict(b.obj->health(static_cast<std::uint8_t>(node))); })
        .def("process", [](HbConsumerBox& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.obj->process(now ? *now : b.clock->now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](HbConsumerBox& b) { b.obj->start(); })
        .def("stop", [](HbConsumerBox& b) { py::gil_scoped_release nogil; b.obj->stop(); })
        .def("set_callback", [](HbConsumerBox& b, py::object cb) {
                 if (cb.is_none()) { b.obj->on_event = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.obj->on_event = [call](std::uint8_t n, HeartbeatEvent e, NodeState s) {
                     call(n, std::string(to_string(e)), std::string(to_string(s)));
                 };
             }, py::arg("callback"), "callback(node, event, state); events: started, lost, back, reset, state-changed, unknown-state.")
        .def_property_readonly("ignored_frames", [](HbConsumerBox& b) { return b.obj->ignored_frames(); });

    py::class_<HbProducerBox, std::shared_ptr<HbProducerBox>>(m, "HeartbeatProducer")
        .def(py::init([](BusPtr bus, int node, double period, py::object state, ClockPtr clock) {
                 check_node(node, false);
                 auto b = std::make_shared<HbProducerBox>();
                 b->bus = bus;
                 b->clock = clock_or_real(clock);
                 std::function<NodeState()> fn;
                 if (py::isinstance<py::str>(state)) {
                     auto st = node_state_from_name(state.cast<std::string>());
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
                         return node_state_from_name((*holder)().cast<std::string>());
                     };
                 }
                 b->obj = make_nogil<HeartbeatProducer>(*bus, *b->clock, static_cast<std::uint8_t>(node),
                                                        std::chrono::nanoseconds(static_cast<std::int64_t>(period * 1e9)), fn);
                 return b;
             }), py::arg("bus"), py::arg("node"), py::arg("period"), py::arg("state") = "OPERATIONAL",
             py::arg("clock") = nullptr)
        .def("send_boot_up", [](HbProducerBox& b) { py::gil_scoped_release nogil; b.obj->send_boot_up(); })
        .def("process", [](HbProducerBox& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.obj->process(now ? *now : b.clock->now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](HbProducerBox& b) { b.obj->start(); })
        .def("stop", [](HbProducerBox& b) { py::gil_scoped_release nogil; b.obj->stop(); })
        .def_property_readonly("send_failures", [](HbProducerBox& b) { return b.obj->send_failures(); },
                               "heartbeats the bus refused (closed, full, link down) while started")
        .def_property_readonly("sent", [](HbProducerBox& b) { return b.obj->sent(); });

    // ---- EMCY -------------------------------------------------------------------
    py::class_<EmcyConsumerBox, std::shared_ptr<EmcyConsumerBox>>(m, "EmcyConsumer",
        "Collects EMCY messages: bounded history and active codes per node.")
        .def(py::init([](BusPtr bus, std::size_t history) {
                 auto b = std::make_shared<EmcyConsumerBox>();
                 b->bus = bus;
                 b->obj = make_nogil<EmcyConsumer>(*bus, history);
                 return b;
             }), py::arg("bus"), py::arg("history") = 32)
        .def("history", [](EmcyConsumerBox& b, int node) {
                 check_node(node, false);
                 py::list l;
                 for (auto& e : b.obj->history(static_cast<std::uint8_t>(node))) l.append(emcy_dict(e));
                 return l;
             }, py::arg("node"))
        .def("active", [](EmcyConsumerBox& b, int node) { check_node(node, false); return b.obj->active(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("clear", [](EmcyConsumerBox& b, int node) { check_node(node, false); b.obj->clear(static_cast<std::uint8_t>(node)); }, py::arg("node"))
        .def("wait", [](EmcyConsumerBox& b, int node, const py::object& t) -> py::object {
                 check_node(node, true);
                 auto to = timeout_of(t);
                 std::optional<EmcyMessage> r;
                 {
                     py::gil_scoped_release nogil;
                     r = b.obj->wait(static_cast<std::uint8_t>(node), to);
                 }
                 if (!r) return py::none();
                 return emcy_dict(*r);
             }, py::arg("node") = 0, py::arg("timeout") = 1.0)
        .def("set_callback", [](EmcyConsumerBox& b, py::object cb) {
                 if (cb.is_none()) { b.obj->on_emcy = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.obj->on_emcy = [call](const EmcyMessage& e) {
                     py::gil_scoped_acquire gil;
                     call(emcy_dict(e));
                 };
             }, py::arg("callback"))
        .def_property_readonly("received", [](EmcyConsumerBox& b) { return b.obj->received(); })
        .def_property_readonly("ignored_frames", [](EmcyConsumerBox& b) { return b.obj->ignored_frames(); });

    py::class_<EmcyProducerBox, std::shared_ptr<EmcyProducerBox>>(m, "EmcyProducer")
        .def(py::init([](BusPtr bus, int node, std::uint16_t inhibit, std::size_t queue, ClockPtr clock) {
                 check_node(node, false);
                 auto b = std::make_shared<EmcyProducerBox>();
                 b->bus = bus;
                 b->clock = clock_or_real(clock);
                 b->obj = make_nogil<EmcyProducer>(*bus, *b->clock, static_cast<std::uint8_t>(node), inhibit, queue);
                 return b;
             }), py::arg("bus"), py::arg("node"), py::arg("inhibit_100us") = 0, py::arg("queue_limit") = 16,
             py::arg("clock") = nullptr)
        .def("report", [](EmcyProducerBox& b, std::uint16_t code, std::uint8_t reg, const py::bytes& data) {
                 auto d = from_bytes(data);
                 if (d.size() > 5) throw InvalidArgument("EMCY manufacturer data: at most 5 bytes");
                 std::array<std::uint8_t, 5> msef{};
                 std::copy(d.begin(), d.end(), msef.begin());
                 py::gil_scoped_release nogil;
                 return b.obj->report(code, reg, msef);
             }, py::arg("code"), py::arg("register") = 0, py::arg("data") = py::bytes())
        .def("process", [](EmcyProducerBox& b, std::optional<Nanos> now) {
                 py::gil_scoped_release nogil;
                 return b.obj->process(now ? *now : b.clock->now());
             }, py::arg("now_ns") = py::none())
        .def("start", [](EmcyProducerBox& b) { b.obj->start(); })
        .def("stop", [](EmcyProducerBox& b) { py::gil_scoped_release nogil; b.obj->stop(); })
        .def_property_readonly("pending", [](EmcyProducerBox& b) { return b.obj->pending(); })
        .def_property_readonly("sent", [](EmcyProducerBox& b) { return b.obj->sent(); })
        .def_property_readonly("dropped", [](EmcyProducerBox& b) { return b.obj->dropped(); });

    // ---- SYNC -------------------------------------------------------------------
    py::class_<SyncProducerBox, std::shared_ptr<SyncProducerBox>>(m, "SyncProducer",
        "SYNC on a C++ thread; jitter() reports the period error statistics.")
        .def(py::init([](BusPtr bus, double period, int overflow, std::uint32_t cob_id) {
                 if (!(period > 0)) throw InvalidArgument("SYNC period must be > 0 s");
                 if (overflow < 0 || overflow > 240) throw InvalidArgument("SYNC counter overflow must be 0 or 2-240");
                 auto b = std::make_shared<SyncProducerBox>();
                 b->bus = bus;
                 b->obj = make_nogil<SyncProducer>(*bus, std::chrono::nanoseconds(static_cast<std::int64_t>(period * 1e9)),
                                                   static_cast<std::uint8_t>(overflow), cob_id);
                 return b;
             }), py::arg("bus"), py::arg("period"), py::arg("counter_overflow") = 0, py::arg("cob_id") = kSyncCobId)
        .def("start", [](SyncProducerBox& b, bool realtime) { b.obj->start(realtime); }, py::arg("realtime") = false,
             "realtime=True asks for SCHED_FIFO; see realtime_granted.")
        .def("stop", [](SyncProducerBox& b) { py::gil_scoped_release nogil; b.obj->stop(); })
        .def_property_readonly("running", [](SyncProducerBox& b) { return b.obj->running(); })
        .def_property_readonly("realtime_granted", [](SyncProducerBox& b) { return b.obj->realtime_granted(); })
        .def_property_readonly("sent", [](SyncProducerBox& b) { return b.obj->sent(); })
        .def("jitter", [](SyncProducerBox& b) {
                 auto j = b.obj->jitter();
                 py::dict d;
                 d["count"] = j.count;
                 d["min_ns"] = j.min_ns;
                 d["mean_ns"] = j.mean_ns;
                 d["max_ns"] = j.max_ns;
                 d["p99_abs_ns"] = j.p99_abs_ns;
                 d["max_abs_ns"] = j.max_abs_ns;
                 return d;
             })
        .def("reset_stats", [](SyncProducerBox& b) { b.obj->reset_stats(); });

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
                 if (values.size() != l.size())
                     throw InvalidArgument("PDO pack: " + std::to_string(values.size()) + " values for " +
                                           std::to_string(l.size()) + " entries");
                 std::uint64_t v[PdoLayout::kMaxEntries];
                 for (std::size_t i = 0; i < values.size(); ++i) v[i] = static_cast<std::uint64_t>(values[i]);
                 std::uint8_t out[8];
                 const unsigned n = l.pack(v, out);
                 return to_bytes(std::span<const std::uint8_t>(out, n));
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

    py::class_<PdoReceiverBox, std::shared_ptr<PdoReceiverBox>>(m, "PdoReceiver",
        "Receives a device's TPDO on the bus and keeps the latest values.")
        .def(py::init([](BusPtr bus, std::uint32_t cob_id, const py::iterable& entries) {
                 auto b = std::make_shared<PdoReceiverBox>();
                 b->bus = bus;
                 b->obj = make_nogil<PdoReceiver>(*bus, cob_id, entries_from(entries));
                 return b;
             }), py::arg("bus"), py::arg("cob_id"), py::arg("entries"))
        .def_property_readonly("values", [](PdoReceiverBox& b) { return b.obj->values(); })
        .def("value", [](PdoReceiverBox& b, std::uint16_t i, std::uint8_t s) { return b.obj->value(i, s); },
             py::arg("index"), py::arg("subindex") = 0)
        .def_property_readonly("received", [](PdoReceiverBox& b) { return b.obj->received(); })
        .def_property_readonly("short_frames", [](PdoReceiverBox& b) { return b.obj->short_frames(); })
        .def("wait_newer", [](PdoReceiverBox& b, std::uint64_t after, const py::object& t) {
                 auto to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 return b.obj->wait_newer(after, to);
             }, py::arg("after"), py::arg("timeout") = 1.0)
        .def("request", [](PdoReceiverBox& b) { py::gil_scoped_release nogil; b.obj->request(); })
        .def("set_callback", [](PdoReceiverBox& b, py::object cb) {
                 if (cb.is_none()) { b.obj->on_receive = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 b.obj->on_receive = [call](const std::vector<std::uint64_t>& v, Nanos ts) { call(v, ts); };
             }, py::arg("callback"), "callback(values, timestamp_ns) on the bus thread.");

    py::class_<PdoSenderBox, std::shared_ptr<PdoSenderBox>>(m, "PdoSender")
        .def(py::init([](BusPtr bus, std::uint32_t cob_id, const py::iterable& entries) {
                 auto b = std::make_shared<PdoSenderBox>();
                 b->bus = bus;
                 b->obj = std::make_shared<PdoSender>(*bus, cob_id, entries_from(entries));
                 return b;
             }), py::arg("bus"), py::arg("cob_id"), py::arg("entries"))
        .def("send", [](PdoSenderBox& b, const std::vector<std::int64_t>& values, const py::object& t) {
                 std::vector<std::uint64_t> v(values.begin(), values.end());
                 auto to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 b.obj->send(v, to);
             }, py::arg("values"), py::arg("timeout") = 1.0);

    m.def("pdo_write_config",
          [](const py::object& sdo, int node, bool tpdo, unsigned number, std::optional<std::uint32_t> cob_id,
             bool enabled, std::optional<int> ttype, std::optional<int> inhibit, std::optional<int> timer,
             std::optional<int> sync_start, std::optional<py::iterable> mapping, const std::string& procedure) {
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
              if (procedure == "cia301") p = PdoProcedure::Cia301;
              else if (procedure == "direct") p = PdoProcedure::Direct;
              else throw InvalidArgument("procedure must be 'cia301' or 'direct'");
              py::gil_scoped_release nogil;
              write_pdo(*box.access, static_cast<std::uint8_t>(node), c, p);
          },
          py::arg("sdo"), py::arg("node"), py::arg("tpdo"), py::arg("number"), py::arg("cob_id") = py::none(),
          py::arg("enabled") = true, py::arg("transmission_type") = py::none(), py::arg("inhibit_100us") = py::none(),
          py::arg("event_timer_ms") = py::none(), py::arg("sync_start") = py::none(), py::arg("mapping") = py::none(),
          py::arg("procedure") = "cia301");
    m.def("pdo_read_config", [](const py::object& sdo, int node, bool tpdo, unsigned number) {
              check_node(node, false);
              auto box = make_sdo(sdo, node);
              PdoConfig c;
              {
                  py::gil_scoped_release nogil;
                  c = read_pdo(*box.access, static_cast<std::uint8_t>(node), tpdo, number);
              }
              py::dict d;
              d["tpdo"] = c.tpdo;
              d["number"] = c.number;
              d["cob_id"] = c.cob_id;
              d["enabled"] = c.enabled;
              d["transmission_type"] = c.transmission_type;
              d["inhibit_100us"] = c.inhibit_100us;
              d["event_timer_ms"] = c.event_timer_ms;
              d["sync_start"] = c.sync_start;
              d["mapping"] = entries_to(*c.mapping);
              return d;
          }, py::arg("sdo"), py::arg("node"), py::arg("tpdo"), py::arg("number"));

    // ---- CiA 402 ------------------------------------------------------------------
    m.def("ds402_decode_statusword", [](std::uint16_t sw) { return std::string(to_string(decode_statusword(sw))); },
          py::arg("statusword"), "State name; 'UNKNOWN' for patterns outside the table.");
    m.def("ds402_next_step", [](const std::string& from, const std::string& to) -> py::object {
              auto s = next_step(ds402_from_name(from), ds402_from_name(to));
              if (!s) return py::none();
              return py::make_tuple(s->controlword, s->transition);
          }, py::arg("from_state"), py::arg("to_state"));

    py::class_<Ds402HostBox, std::shared_ptr<Ds402HostBox>>(m, "Ds402Host",
        "CiA 402 power state machine and PP/PV/HM handshakes, driven from the host.")
        .def(py::init([](const py::object& sdo, int node, double timeout, double poll) {
                 check_node(node, false);
                 auto b = std::make_shared<Ds402HostBox>();
                 b->sdo = make_sdo(sdo, node);
                 Ds402HostOptions o;
                 o.timeout = std::chrono::nanoseconds(static_cast<std::int64_t>(timeout * 1e9));
                 o.sdo_poll = std::chrono::nanoseconds(static_cast<std::int64_t>(poll * 1e9));
                 b->obj = make_nogil<Ds402Host>(*b->sdo.access, static_cast<std::uint8_t>(node), o);
                 return b;
             }), py::arg("sdo"), py::arg("node"), py::arg("timeout") = 2.0, py::arg("poll") = 0.005)
        .def("use_statusword_pdo", [](Ds402HostBox& b, std::shared_ptr<PdoReceiverBox> rx) {
                 b.obj->use_statusword_pdo(rx ? rx->obj.get() : nullptr);
                 b.sw_pdo = rx;
             }, py::arg("receiver"))
        .def_property_readonly("statusword", [](Ds402HostBox& b) { py::gil_scoped_release nogil; return b.obj->read_statusword(); })
        .def_property_readonly("state", [](Ds402HostBox& b) {
                 Ds402State s;
                 {
                     py::gil_scoped_release nogil;
                     s = b.obj->state();
                 }
                 return std::string(to_string(s));
             })
        .def("write_controlword", [](Ds402HostBox& b, std::uint16_t c) { py::gil_scoped_release nogil; b.obj->write_controlword(c); })
        .def("go_to", [](Ds402HostBox& b, const std::string& s) {
                 auto t = ds402_from_name(s);
                 py::gil_scoped_release nogil;
                 b.obj->go_to(t);
             }, py::arg("state"))
        .def("fault_reset", [](Ds402HostBox& b) { py::gil_scoped_release nogil; b.obj->fault_reset(); })
        .def("quick_stop", [](Ds402HostBox& b) { py::gil_scoped_release nogil; b.obj->quick_stop(); })
        .def("wait_statusword", [](Ds402HostBox& b, std::uint16_t mask, std::uint16_t value, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 return b.obj->wait_statusword(mask, value, to);
             }, py::arg("mask"), py::arg("value"), py::arg("timeout") = py::none())
        .def("set_mode", [](Ds402HostBox& b, int mode) {
                 py::gil_scoped_release nogil;
                 b.obj->set_mode(static_cast<OpMode>(mode));
             }, py::arg("mode"))
        .def_property_readonly("mode", [](Ds402HostBox& b) { py::gil_scoped_release nogil; return static_cast<int>(b.obj->mode()); })
        .def("move_to", [](Ds402HostBox& b, std::int32_t target, bool relative, bool immediate) {
                 py::gil_scoped_release nogil;
                 b.obj->move_to(target, relative, immediate);
             }, py::arg("target"), py::arg("relative") = false, py::arg("immediate") = true)
        .def("wait_target_reached", [](Ds402HostBox& b, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 py::gil_scoped_release nogil;
                 b.obj->wait_target_reached(to);
             }, py::arg("timeout") = py::none())
        .def("set_velocity", [](Ds402HostBox& b, std::int32_t v) { py::gil_scoped_release nogil; b.obj->set_velocity(v); })
        .def("home", [](Ds402HostBox& b, std::optional<int> method, const py::object& t) {
                 std::optional<std::chrono::nanoseconds> to;
                 if (!t.is_none()) to = timeout_of(t);
                 std::optional<std::int8_t> mth;
                 if (method) mth = static_cast<std::int8_t>(*method);
                 py::gil_scoped_release nogil;
                 b.obj->home(mth, to);
             }, py::arg("method") = py::none(), py::arg("timeout") = py::none());

    py::class_<Ds402Device, std::shared_ptr<Ds402Device>>(m, "Ds402Device",
        "Device-side CiA 402 state machine for simulators.")
        .def(py::init([] { return std::make_shared<Ds402Device>(); }))
        .def_property_readonly("state", [](const Ds402Device& d) { return std::string(to_string(d.state())); })
        .def_property_readonly("statusword", &Ds402Device::statusword)
        .def_property_readonly("controlword", &Ds402Device::controlword)
        .def("on_controlword", &Ds402Device::on_controlword, py::arg("controlword"))
        .def("set_mode", &Ds402Device::set_mode, py::arg("mode"), "0 or the SDO abort code (0x06090030).")
        .def_property_readonly("mode", &Ds402Device::mode)
        .def("set_supported_modes", &Ds402Device::set_supported_modes)
        .def("set_abort_connection_option", &Ds402Device::set_abort_connection_option)
        .def("set_quick_stop_option", &Ds402Device::set_quick_stop_option)
        .def("fault", &Ds402Device::fault, py::arg("error_code"))
        .def("fault_reaction_done", &Ds402Device::fault_reaction_done)
        .def("loss_of_master", &Ds402Device::loss_of_master)
        .def("motion_stopped", &Ds402Device::motion_stopped)
        .def("set_status_bits", &Ds402Device::set_status_bits, py::arg("mask"), py::arg("value"))
        .def_property_readonly("last_error_code", &Ds402Device::last_error_code)
        .def_property_readonly("drive_enabled", &Ds402Device::drive_enabled);

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
        .def("mapping", [](PdoService& s, bool tpdo, unsigned n) { return entries_to(s.engine().mapping(tpdo, n)); },
             py::arg("tpdo"), py::arg("number"))
        .def("cob_id", [](PdoService& s, bool tpdo, unsigned n) { return s.engine().cob_id(tpdo, n); },
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
                 auto c = s.engine().counters();
                 py::dict d;
                 d["tpdo_sent"] = c.tpdo_sent;
                 d["rpdo_applied"] = c.rpdo_applied;
                 d["rpdo_ignored"] = c.rpdo_ignored;
                 d["rpdo_length_errors"] = c.rpdo_length_errors;
                 d["sync_received"] = c.sync_received;
                 d["sync_errors"] = c.sync_errors;
                 d["rtr_ignored"] = c.rtr_ignored;
                 d["collisions"] = c.collisions;
                 return d;
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
        .def("health", [](HeartbeatService& s, int node) { check_node(node, false); return health_dict(s.health(static_cast<std::uint8_t>(node))); })
        .def_property_readonly("heartbeats_sent", &HeartbeatService::heartbeats_sent)
        .def("set_lost_callback", [](HeartbeatService& s, py::object cb) {
                 if (cb.is_none()) { s.on_lost = nullptr; return; }
                 PyCallable call(cb.cast<py::function>());
                 s.on_lost = [call](std::uint8_t n) { call(n); };
             }, py::arg("callback"), "callback(node) when a consumed heartbeat is lost (e.g. Ds402Device.loss_of_master).");

    // ---- scanner ------------------------------------------------------------------
    m.def("scan_network", [](BusPtr bus, int first, int last, double sdo_timeout, double listen, bool probe_sdo,
                             bool identity) {
              if (first < 1 || last > 127 || first > last) throw InvalidArgument("scan range must be within 1-127");
              ScanOptions o;
              o.first = static_cast<std::uint8_t>(first);
              o.last = static_cast<std::uint8_t>(last);
              o.sdo_timeout = std::chrono::nanoseconds(static_cast<std::int64_t>(sdo_timeout * 1e9));
              o.listen = std::chrono::nanoseconds(static_cast<std::int64_t>(listen * 1e9));
              o.probe_sdo = probe_sdo;
              o.read_identity = identity;
              std::vector<ScanResult> res;
              {
                  py::gil_scoped_release nogil;
                  res = scan_network(*bus, o);
              }
              py::list out;
              for (auto& r : res) {
                  py::dict d;
                  d["node"] = r.node_id;
                  d["sdo_answered"] = r.sdo_answered;
                  d["heard_heartbeat"] = r.heard_heartbeat;
                  d["heard_boot_up"] = r.heard_boot_up;
                  d["state"] = to_string(r.state);
                  d["device_type"] = r.device_type;
                  d["device_type_abort"] = r.device_type_abort;
                  d["vendor_id"] = r.vendor_id;
                  d["product_code"] = r.product_code;
                  d["revision"] = r.revision;
                  d["serial_number"] = r.serial_number;
                  out.append(d);
              }
              return out;
          }, py::arg("bus"), py::arg("first") = 1, py::arg("last") = 127, py::arg("sdo_timeout") = 0.2,
          py::arg("listen") = 0.0, py::arg("probe_sdo") = true, py::arg("identity") = true);
}
