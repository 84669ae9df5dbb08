// Bindings for cpp/motorbus/drives/unitek: codec, register table, client with
// numpy streams, simulator, profile model.  Only conversions and GIL handling.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "../common.hpp"
#include "../sim_device.hpp"
#include "../errors.hpp"
#include "motorbus/drives/unitek/client.hpp"
#include "motorbus/drives/unitek/codec.hpp"
#include "motorbus/drives/unitek/poll_source.hpp"
#include "motorbus/drives/unitek/profile.hpp"
#include "motorbus/drives/unitek/sim.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;
using namespace motorbus::unitek;
using motorbus::py_helpers::blocking_call;
using motorbus::py_helpers::duration_arg;

namespace {

std::vector<std::uint8_t> bytes_of(const py::handle& h, const char* name) {
    if (py::isinstance<py::bytes>(h) || py::isinstance<py::bytearray>(h)) {
        std::string s = py::bytes(py::reinterpret_borrow<py::object>(h)).cast<std::string>();
        return {s.begin(), s.end()};
    }
    try {
        return h.cast<std::vector<std::uint8_t>>();
    } catch (const py::cast_error&) {
        throw InvalidArgument(std::string(name) + ": bytes or a list of 0..255");
    }
}

py::bytes to_bytes(const std::vector<std::uint8_t>& v) {
    return py::bytes(reinterpret_cast<const char*>(v.data()), v.size());
}

std::uint8_t regid_arg(std::int64_t r) {
    if (r < 0 || r > 0xFF) throw InvalidArgument("regid: 0x00..0xFF, not " + std::to_string(r));
    return static_cast<std::uint8_t>(r);
}

void fill_frame_error(py::object& exc, const FrameError& e) {
    exc.attr("data") = py::bytes(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
    exc.attr("byte") = e.byte;
}
void fill_unknown(py::object& exc, const UnknownRegister& e) { exc.attr("regid") = e.regid; }

std::shared_ptr<py::function> hold(py::function f) {
    return std::shared_ptr<py::function>(new py::function(std::move(f)), [](py::function* p) {
        if (!Py_IsInitialized()) return;
        py::gil_scoped_acquire gil;
        delete p;
    });
}

// Destroyed without the GIL: the client's receive callbacks take the GIL to run a
// Python on_status hook, so deleting it while holding the GIL could deadlock.
struct ReleaseGilDeleteClient {
    void operator()(Client* c) const {
        if (Py_IsInitialized() && PyGILState_Check()) {
            py::gil_scoped_release nogil;
            delete c;
        } else {
            delete c;
        }
    }
};
using ClientPtr = std::unique_ptr<Client, ReleaseGilDeleteClient>;

// A Python view on a Stream: its ring as numpy, and a read cursor.
struct StreamView {
    std::shared_ptr<Stream> s;
    std::uint64_t cursor = 0;
    std::uint64_t lost = 0;
};

py::tuple stream_read(StreamView& v, std::int64_t max) {
    const std::size_t cap = v.s->ring.capacity();
    const std::size_t n0 = max < 0 ? cap : static_cast<std::size_t>(std::min<std::int64_t>(max, static_cast<std::int64_t>(cap)));
    py::array_t<std::int64_t> t(static_cast<py::ssize_t>(n0)), val(static_cast<py::ssize_t>(n0));
    std::size_t n;
    {
        py::gil_scoped_release nogil;
        n = v.s->ring.read(v.cursor, t.mutable_data(), val.mutable_data(), n0, v.lost);
    }
    t.resize({static_cast<py::ssize_t>(n)});
    val.resize({static_cast<py::ssize_t>(n)});
    return py::make_tuple(t, val);
}

}  // namespace

static void bind_unitek_errors_and_profile(py::module_& m) {
    py_errors::add_error_classes({
        {"UnitekFrameError", {"ProtocolError"},
         "A UNITEK frame that breaks the protocol (wrong DLC...); .byte is the 0-based index of the byte at fault, .data the frame."},
        {"UnitekUnknownRegister", {"InvalidArgument", "KeyError"},
         "A REGID the register table does not know (extend it from the NDrive list); .regid."},
        {"UnitekCyclicLimit", {"InvalidArgument"}, "A 9th cyclic register: the drive transmits at most 8 (002 ex 9)."},
    });
    py_errors::translate<UnknownRegister, fill_unknown>(py_errors::error_class("UnitekUnknownRegister"));
    py_errors::translate<CyclicLimit>(py_errors::error_class("UnitekCyclicLimit"));
    py_errors::translate<FrameError, fill_frame_error>(py_errors::error_class("UnitekFrameError"));

    // ---- profile (existing) ----
    py::class_<RampParams>(m, "RampParams")
        .def(py::init([](double nmax, double acc, double dec) {
                 RampParams p{nmax, acc, dec};
                 p.validate();
                 return p;
             }),
             py::arg("n_max_rpm") = 3000.0, py::arg("acc_ramp_ms") = 1000.0, py::arg("dec_ramp_ms") = 1000.0)
        .def_readwrite("n_max_rpm", &RampParams::n_max_rpm)
        .def_readwrite("acc_ramp_ms", &RampParams::acc_ramp_ms)
        .def_readwrite("dec_ramp_ms", &RampParams::dec_ramp_ms);
    m.def("speed_profile", &speed_profile, py::arg("start"), py::arg("speed_num"), py::arg("params"),
          py::arg("hold") = 0.0);
}

static void bind_unitek_registers(py::module_& m) {
    // ---- register table ----
    py::enum_<Access>(m, "Access")
        .value("RW", Access::ReadWrite).value("RO", Access::ReadOnly).value("WO", Access::WriteOnly);
    py::enum_<Quantity>(m, "Quantity")
        .value("RAW", Quantity::Raw).value("SPEED", Quantity::Speed).value("POSITION", Quantity::Position)
        .value("CURRENT", Quantity::Current).value("TORQUE", Quantity::Torque).value("TIME", Quantity::Time);
    py::class_<Register>(m, "Register", "One row of the UNITEK register table.")
        .def(py::init([](std::int64_t regid, std::string name, int bits, bool is_signed, Access access,
                         Quantity quantity, std::string unit, double scale, std::optional<std::int64_t> lo,
                         std::optional<std::int64_t> hi, std::string description) {
                 Register r;
                 r.regid = regid_arg(regid);
                 r.name = std::move(name);
                 r.bits = bits;
                 r.is_signed = is_signed;
                 r.access = access;
                 r.quantity = quantity;
                 r.unit = std::move(unit);
                 r.scale = scale;
                 if (lo.has_value() != hi.has_value()) throw InvalidArgument("unitek register range: give min and max, or neither");
                 if (lo) {
                     if (*lo > *hi) throw InvalidArgument("unitek register range: min > max");
                     r.min = *lo;
                     r.max = *hi;
                 } else {
                     r.min = 1;
                     r.max = 0;
                 }
                 r.description = std::move(description);
                 return r;
             }),
             py::arg("regid"), py::arg("name"), py::arg("bits") = 16, py::arg("signed") = false,
             py::arg("access") = Access::ReadWrite, py::arg("quantity") = Quantity::Raw, py::arg("unit") = "",
             py::arg("scale") = 1.0, py::arg("min") = py::none(), py::arg("max") = py::none(),
             py::arg("description") = "")
        .def_readonly("regid", &Register::regid)
        .def_readonly("name", &Register::name)
        .def_readonly("bits", &Register::bits)
        .def_readonly("signed", &Register::is_signed)
        .def_readonly("access", &Register::access)
        .def_readonly("quantity", &Register::quantity)
        .def_readonly("unit", &Register::unit)
        .def_readonly("scale", &Register::scale)
        .def_property_readonly("min", &Register::lo)
        .def_property_readonly("max", &Register::hi)
        .def_readonly("description", &Register::description)
        .def_property_readonly("readable", &Register::readable)
        .def_property_readonly("writable", &Register::writable)
        .def("from_raw", &Register::from_raw, py::arg("raw"), py::arg("bits"))
        .def("__repr__", [](const Register& r) {
            return "<UnitekRegister 0x" + hex(std::vector<std::uint8_t>{r.regid}) + " " + r.name + " " +
                   std::to_string(r.bits) + "-bit>";
        });
    py::class_<RegisterTable>(m, "RegisterTable", "The UNITEK REGIDs: the 12 documented ones, extendable.")
        .def(py::init([](bool builtin) { return builtin ? RegisterTable::builtin() : RegisterTable{}; }),
             py::arg("builtin") = true)
        .def("add", &RegisterTable::add, py::arg("register"))
        .def("__getitem__", [](const RegisterTable& t, const py::object& key) {
            if (py::isinstance<py::str>(key)) return t.at(key.cast<std::string>());
            return t.at(regid_arg(key.cast<std::int64_t>()));
        })
        .def("__contains__", [](const RegisterTable& t, const py::object& key) {
            if (py::isinstance<py::str>(key)) return t.find(key.cast<std::string>()) != nullptr;
            const auto v = key.cast<std::int64_t>();
            return v >= 0 && v <= 0xFF && t.find(static_cast<std::uint8_t>(v)) != nullptr;
        })
        .def("__len__", &RegisterTable::size)
        .def("rows", &RegisterTable::rows);

    py::class_<Scalings>(m, "Scalings", "§6.1 scalings: N max, 65536 num/rev, device current.")
        .def(py::init([](double n, double c, double inum, double ia) {
                 Scalings s{n, c, inum, ia};
                 s.validate();
                 return s;
             }),
             py::arg("n_max_rpm") = 3000.0, py::arg("counts_per_rev") = 65536.0, py::arg("i_max_num") = 160.0,
             py::arg("i_max_a") = 10.0)
        .def_readonly("n_max_rpm", &Scalings::n_max_rpm)
        .def_readonly("counts_per_rev", &Scalings::counts_per_rev)
        .def_readonly("i_max_num", &Scalings::i_max_num)
        .def_readonly("i_max_a", &Scalings::i_max_a)
        .def("to_physical", &Scalings::to_physical, py::arg("register"), py::arg("num"))
        .def("to_num", &Scalings::to_num, py::arg("register"), py::arg("value"));
    m.def("device_currents", [] {
        py::list out;
        for (const auto& d : device_currents())
            out.append(py::dict(py::arg("device") = d.device, py::arg("i100_mv") = d.i100_mv,
                                py::arg("i100_num") = d.i100_num, py::arg("i_rms_a") = d.i_rms_a,
                                py::arg("i_peak_a") = d.i_peak_a, py::arg("i_max_num") = d.i_max_num,
                                py::arg("i_max_a") = d.i_max_a));
        return out;
    });
    m.def("continuous_current_num", [](const std::string& device, double amps) {
        return continuous_current_num(device_current(device), amps);
    }, py::arg("device"), py::arg("amps"));
    m.def("effective_current_limit_num", [](const std::string& device, std::int64_t motor_limit_num) {
        return effective_current_limit_num(device_current(device), motor_limit_num);
    }, py::arg("device"), py::arg("motor_limit_num"),
       "§6.1: the smaller of the motor's and the device's peak current (num)");
    m.def("bit_timings", [] {
        py::list out;
        for (const auto& b : bit_timings())
            out.append(py::dict(py::arg("kbit_s") = b.kbit_s, py::arg("btr") = b.btr,
                                py::arg("max_line_m") = b.max_line_m));
        return out;
    }, "§3.1: bit rate (kbit/s), BTR setting value, longest line (m)");
    m.def("btr_for_bit_rate", [](double bit_s) { return bit_timing_for_bit_rate(bit_s).btr; },
          py::arg("bit_rate"));
    m.def("bit_rate_for_btr", [](std::int64_t btr) {
        if (btr < 0 || btr > 0xFFFF) throw InvalidArgument("unitek BTR: a 16-bit setting value");
        return bit_timing_for_btr(static_cast<std::uint16_t>(btr)).bit_rate();
    }, py::arg("btr"));
    m.def("analog_command_num", &analog_command_num, py::arg("volts"),
          "§6.1: the num of an analog command (10 V = 29490)");
    m.def("sim_default_table", &sim_default_table);
}

static void bind_unitek_codec(py::module_& m) {
    // ---- codec ----
    m.def("encode_write", [](std::int64_t regid, std::int64_t value, int bits) {
        return to_bytes(encode_write(regid_arg(regid), value, bits));
    }, py::arg("regid"), py::arg("value"), py::arg("bits") = 16);
    m.def("encode_request", [](std::int64_t regid, std::int64_t interval) {
        if (interval < 0 || interval > 255) throw InvalidArgument("interval: 0 (once), 1..254 ms, 255 (stop)");
        return to_bytes(encode_request(regid_arg(regid), static_cast<std::uint8_t>(interval)));
    }, py::arg("regid"), py::arg("interval"));
    m.def("decode_to_drive", [](const py::object& data) {
        const auto t = decode_to_drive(bytes_of(data, "data"));
        return py::make_tuple(t.regid, t.value, t.value_bits);
    }, py::arg("data"), "(regid, raw value, bits) as the drive evaluates the frame; UnitekFrameError for DLC < 3 or > 8");
    m.def("decode_from_drive", [](const py::object& data) {
        const auto f = decode_from_drive(bytes_of(data, "data"));
        return py::make_tuple(f.regid, f.value, f.value_bits);
    }, py::arg("data"), "(regid, raw value, bits) of a frame from the drive; UnitekFrameError unless DLC 4 or 6");
}

static void bind_unitek_client(py::module_& m) {
    // ---- client ----
    py::class_<StreamView, std::shared_ptr<StreamView>>(m, "Stream",
        "One cyclic register: a ring of (timestamp ns, value num) filled by the bus thread.")
        .def_property_readonly("regid", [](const StreamView& v) { return v.s->regid; })
        .def_property_readonly("interval_ms", [](const StreamView& v) { return v.s->interval_ms.load(); })
        .def_property_readonly("active", [](const StreamView& v) { return v.s->active.load(); })
        .def_property_readonly("capacity", [](const StreamView& v) { return v.s->ring.capacity(); })
        .def_property_readonly("count", [](const StreamView& v) { return v.s->ring.count(); },
                               "samples received since the subscription")
        .def_property_readonly("lost", [](const StreamView& v) { return v.lost; },
                               "samples overwritten before read() took them")
        .def("read", &stream_read, py::arg("max") = -1,
             "(timestamps int64 ns, values int64 num) received since the last read, oldest first")
        .def_property_readonly("times", [](py::object self) {
            auto& v = self.cast<StreamView&>();
            return py::array_t<std::int64_t>({static_cast<py::ssize_t>(v.s->ring.capacity())}, {8},
                                             v.s->ring.times(), self);
        }, "the whole ring (zero-copy, read-only use; sample k at k % capacity)")
        .def_property_readonly("values", [](py::object self) {
            auto& v = self.cast<StreamView&>();
            return py::array_t<std::int64_t>({static_cast<py::ssize_t>(v.s->ring.capacity())}, {8},
                                             v.s->ring.values(), self);
        });

    py::class_<ClientCounters>(m, "ClientCounters")
        .def_readonly("replies", &ClientCounters::replies)
        .def_readonly("rejected", &ClientCounters::rejected)
        .def_readonly("unsolicited", &ClientCounters::unsolicited)
        .def_readonly("callback_errors", &ClientCounters::callback_errors);

    // The bus and the clock are kept alive by the Python objects (keep_alive), as for every
    // class here that holds a C++ reference.
    py::class_<Client, ClientPtr>(m, "Client", "UNITEK register protocol client over a CAN bus (see client.hpp).")
        .def(py::init([](std::shared_ptr<can::Bus> bus, std::uint32_t rx_id, std::uint32_t tx_id, const py::object& timeout,
                         std::optional<RegisterTable> table, std::shared_ptr<Clock> clock) {
                 if (!bus) throw InvalidArgument("bus: None (a motorbus Bus is required)");
                 ClientOptions o;
                 o.rx_id = rx_id;
                 o.tx_id = tx_id;
                 o.timeout = duration_arg(timeout, "timeout");
                 o.clock = clock.get();
                 py::gil_scoped_release nogil;
                 return ClientPtr(new Client(*bus, table ? *table : RegisterTable::builtin(), o));
             }),
             py::arg("bus"), py::arg("rx_id") = kDefaultRxId, py::arg("tx_id") = kDefaultTxId,
             py::arg("timeout") = 0.2, py::arg("table") = py::none(), py::arg("clock") = py::none(),
             py::keep_alive<1, 2>(), py::keep_alive<1, 7>())
        .def_property_readonly("table", [](const Client& c) { return c.table(); })
        .def("add_register", [](Client& c, Register r) { c.add_register(std::move(r)); }, py::arg("register"))
        .def("write", [](Client& c, std::int64_t regid, std::int64_t value) {
            blocking_call([&] { c.write(regid_arg(regid), value); });
        }, py::arg("regid"), py::arg("value"))
        .def("write_raw", [](Client& c, std::int64_t regid, std::int64_t value, int bits) {
            blocking_call([&] { c.write_raw(regid_arg(regid), value, bits); });
        }, py::arg("regid"), py::arg("value"), py::arg("bits") = 16)
        .def("read", [](Client& c, std::int64_t regid, const py::object& timeout) {
            std::optional<std::chrono::nanoseconds> t;
            if (!timeout.is_none()) t = duration_arg(timeout, "timeout");
            const auto r = regid_arg(regid);
            return blocking_call([&] { return c.read(r, t); });
        }, py::arg("regid"), py::arg("timeout") = py::none())
        .def("subscribe", [](Client& c, std::int64_t regid, int interval_ms, std::size_t capacity,
                             const py::object& callback) {
            SampleCallback cb;
            if (!callback.is_none()) {
                if (!PyCallable_Check(callback.ptr())) throw InvalidArgument("callback: a callable (regid, t_ns, value)");
                auto f = hold(callback.cast<py::function>());
                cb = [f](std::uint8_t r, Nanos t, std::int64_t v) {
                    if (py_helpers::interpreter_finalizing()) return;
                    py::gil_scoped_acquire gil;
                    try {
                        (*f)(r, t, v);
                    } catch (py::error_already_set& e) {
                        e.discard_as_unraisable("motorbus unitek stream callback");
                    }
                };
            }
            const auto r = regid_arg(regid);
            auto s = blocking_call([&] { return c.subscribe(r, interval_ms, capacity, std::move(cb)); });
            auto v = std::make_shared<StreamView>();
            v->s = s;
            return v;
        }, py::arg("regid"), py::arg("interval_ms"), py::arg("capacity") = 65536, py::arg("callback") = py::none())
        .def("unsubscribe", [](Client& c, std::int64_t regid) {
            blocking_call([&] { c.unsubscribe(regid_arg(regid)); });
        }, py::arg("regid"))
        .def_property_readonly("cyclic", [](const Client& c) {
            std::vector<std::pair<int, int>> out;
            for (auto& s : c.streams()) out.emplace_back(s->regid, s->interval_ms.load());
            return out;
        })
        .def("enable", [](Client& c) { blocking_call([&] { c.enable(); }); })
        .def("disable", [](Client& c) { blocking_call([&] { c.disable(); }); })
        .def("set_events", [](Client& c, bool on, std::optional<std::uint16_t> mask) {
            blocking_call([&] { c.set_events(on, mask); });
        }, py::arg("on"), py::arg("mask") = py::none())
        .def("on_status", [](Client& c, const py::object& callback) {
            if (callback.is_none()) return c.on_status(nullptr);
            auto f = hold(callback.cast<py::function>());
            c.on_status([f](std::uint32_t st, Nanos t) {
                if (py_helpers::interpreter_finalizing()) return;
                py::gil_scoped_acquire gil;
                try {
                    (*f)(st, t);
                } catch (py::error_already_set& e) {
                    e.discard_as_unraisable("motorbus unitek status callback");
                }
            });
        }, py::arg("callback"))
        .def_property_readonly("last_event_status", [](const Client& c) { return c.last_event_status(); })
        .def_property_readonly("events", [](const Client& c) { return c.events(); })
        .def_property_readonly("mode", [](const Client& c) { return c.mode(); })
        .def("set_receive_id", [](Client& c, std::uint32_t id) { blocking_call([&] { c.set_receive_id(id); }); },
             py::arg("rx_id"))
        .def("store_eeprom", [](Client& c, int level) { blocking_call([&] { c.store_eeprom(level); }); },
             py::arg("level") = 0)
        .def_property_readonly("rx_id", [](const Client& c) { return c.rx_id(); })
        .def_property_readonly("tx_id", [](const Client& c) { return c.tx_id(); })
        .def_property_readonly("counters", [](const Client& c) { return c.counters(); })
        .def("close", [](Client& c) { blocking_call([&] { c.close(); }); });
}

static void bind_unitek_sim(py::module_& m) {
    // ---- simulator ----
    py::class_<SimCounters>(m, "SimCounters")
        .def_readonly("frames_in", &SimCounters::frames_in)
        .def_readonly("ignored", &SimCounters::ignored)
        .def_readonly("malformed", &SimCounters::malformed)
        .def_readonly("unknown", &SimCounters::unknown)
        .def_readonly("refused", &SimCounters::refused)
        .def_readonly("cyclic_refused", &SimCounters::cyclic_refused)
        .def_readonly("frames_out", &SimCounters::frames_out)
        .def_readonly("events_out", &SimCounters::events_out)
        .def_readonly("bit_rate_mismatch", &SimCounters::bit_rate_mismatch);

    // attach / close / attached / describe / power_cycle: the SimulatedDevice base's.
    py::class_<Sim, can::SimulatedDevice, std::shared_ptr<Sim>>(
        m, "Sim", "A simulated UNITEK servo on the register protocol (see sim.hpp).")
        .def(py::init([](std::shared_ptr<Clock> clock, std::uint32_t rx_id, std::uint32_t tx_id, double n_max_rpm,
                         double acc_ramp_ms, double dec_ramp_ms, bool position_control, bool speed_control,
                         bool calibrated, std::int64_t tol_num, std::optional<double> minus_limit_num,
                         std::optional<double> plus_limit_num, std::int64_t torque_continuous_num, int dummy,
                         std::optional<RegisterTable> table, std::string device,
                         std::optional<std::int64_t> motor_i_max_num, std::int64_t btr, int analog_command) {
                 if (!clock) throw InvalidArgument("clock: None (a motorbus Clock is required)");
                 SimConfig c;
                 c.rx_id = rx_id;
                 c.tx_id = tx_id;
                 c.n_max_rpm = n_max_rpm;
                 c.acc_ramp_ms = acc_ramp_ms;
                 c.dec_ramp_ms = dec_ramp_ms;
                 c.position_control = position_control;
                 c.speed_control = speed_control;
                 c.calibrated = calibrated;
                 c.tol_num = tol_num;
                 c.minus_limit_num = minus_limit_num;
                 c.plus_limit_num = plus_limit_num;
                 c.torque_continuous_num = torque_continuous_num;
                 if (dummy < 0 || dummy > 255) throw InvalidArgument("dummy: 0..255");
                 c.dummy = static_cast<std::uint8_t>(dummy);
                 c.device = device;
                 c.motor_i_max_num = motor_i_max_num;
                 if (btr < 0 || btr > 0xFFFF) throw InvalidArgument("unitek sim btr: a 16-bit BTR setting value");
                 c.btr = static_cast<std::uint16_t>(btr);
                 c.analog_command = analog_command;
                 return py_helpers::make_sim<Sim>(std::move(clock), c, table ? *table : sim_default_table());
             }),
             py::arg("clock"), py::arg("rx_id") = kDefaultRxId, py::arg("tx_id") = kDefaultTxId,
             py::arg("n_max_rpm") = 3000.0, py::arg("acc_ramp_ms") = 1000.0, py::arg("dec_ramp_ms") = 1000.0,
             py::arg("position_control") = true, py::arg("speed_control") = true, py::arg("calibrated") = false,
             py::arg("tol_num") = 64, py::arg("minus_limit_num") = -100.0 * 65536,
             py::arg("plus_limit_num") = 100.0 * 65536, py::arg("torque_continuous_num") = 32767,
             py::arg("dummy") = 0, py::arg("table") = py::none(), py::arg("device") = "DS 205/405",
             py::arg("motor_i_max_num") = py::none(), py::arg("btr") = kDefaultBtr, py::arg("analog_command") = 0)
        .def("on_frame", [](Sim& h, const can::Frame& f) {
            py::gil_scoped_release nogil;
            h.on_frame(f);
        }, py::arg("frame"))
        .def("service", [](Sim& h) {
            py::gil_scoped_release nogil;
            return h.service();
        }, "emit every frame due by the clock's now; returns the next due time (ns, -1 none)")
        .def("set_hardware_enable", [](Sim& h, bool on) {
            py::gil_scoped_release nogil;
            h.set_hardware_enable(on);
        }, py::arg("on"))
        .def("force_limit", [](Sim& h, int dir, std::optional<bool> a) {
            py::gil_scoped_release nogil;
            h.force_limit(dir, a);
        }, py::arg("direction"), py::arg("active"))
        .def("force_error", [](Sim& h, std::uint32_t bits) {
            py::gil_scoped_release nogil;
            h.force_error(bits);
        }, py::arg("bits"), "latch NDrive error (0-15: power stage off) / warning (16-31) bits in 0x8F")
        .def("set_analog_input", [](Sim& h, int channel, double volts) {
            py::gil_scoped_release nogil;
            h.set_analog_input(channel, volts);
        }, py::arg("channel"), py::arg("volts"),
           "AIN1/AIN2 (+/- 10 V, 2949 num/V); the speed command when analog_command names the input")
        .def("set_calibrated", [](Sim& h, bool on) {
            py::gil_scoped_release nogil;
            h.set_calibrated(on);
        }, py::arg("on"))
        .def("force_icns", [](Sim& h, std::optional<bool> a) {
            py::gil_scoped_release nogil;
            h.force_icns(a);
        }, py::arg("active"))
        .def_property_readonly("status", [](Sim& h) { return h.status(); })
        .def("value", [](Sim& h, std::int64_t regid) { return h.value(regid_arg(regid)); }, py::arg("regid"))
        .def_property_readonly("position_num", [](Sim& h) { return h.position_num(); })
        .def_property_readonly("speed_num", [](Sim& h) { return h.speed_num(); })
        .def_property_readonly("rx_id", [](Sim& h) { return h.rx_id(); })
        .def_property_readonly("bit_rate", [](Sim& h) { return h.bit_rate(); },
                               "bit/s of its BTR (§3.1 table)")
        .def_property_readonly("bus_bit_rate", [](Sim& h) { return h.bus_bit_rate(); },
                               "bit/s of the bus it is attached to (0: none modelled)")
        .def_property_readonly("tx_id", [](Sim& h) { return h.tx_id(); })
        .def_property_readonly("cyclic", [](Sim& h) {
            std::vector<std::pair<int, int>> out;
            for (auto [r, ms] : h.cyclic()) out.emplace_back(r, ms);
            return out;
        })
        .def("sent", [](Sim& h, std::int64_t regid) { return h.sent(regid_arg(regid)); }, py::arg("regid"))
        .def_property_readonly("counters", [](Sim& h) { return h.counters(); })
        .def_property_readonly("n_max_rpm", [](Sim& h) { return h.config().n_max_rpm; })
        .def("eeprom", [](Sim& h) {
            std::map<int, std::int64_t> out;
            for (auto [k, v] : h.eeprom()) out[k] = v;
            return out;
        })
        .def("on_eeprom_store", [](Sim& h, const py::object& callback) {
            if (callback.is_none()) return h.on_eeprom_store(nullptr);
            auto f = hold(callback.cast<py::function>());
            h.on_eeprom_store([f](const std::map<std::uint8_t, std::int64_t>& values) {
                if (py_helpers::interpreter_finalizing()) return;
                py::gil_scoped_acquire gil;
                try {
                    py::dict d;
                    for (auto [k, v] : values) d[py::int_(k)] = v;
                    (*f)(d);
                } catch (py::error_already_set& e) {
                    e.discard_as_unraisable("motorbus unitek EEPROM store callback");
                }
            });
        }, py::arg("callback"), "callback(dict regid -> value) after each EEPROM store (0x84)")
        .def("load_eeprom", [](Sim& h, const std::map<int, std::int64_t>& values) {
            std::map<std::uint8_t, std::int64_t> in;
            for (auto [k, v] : values) in[regid_arg(k)] = v;
            py::gil_scoped_release nogil;
            h.load_eeprom(in);
        }, py::arg("values"));
}

static void bind_unitek_poll(py::module_& m) {
    // Poll sources (motorbus.Poller) on this client: asking, or capturing cyclic transmissions.
    auto regids_arg = [](const std::vector<std::int64_t>& ids) {
        std::vector<std::uint8_t> r;
        for (auto id : ids) r.push_back(regid_arg(id));
        return r;
    };
    m.def("poll_source", [regids_arg](Client& c, const std::vector<std::int64_t>& regids) -> std::shared_ptr<poll::Source> {
              auto r = regids_arg(regids);
              return std::make_shared<PollSource>(c, std::move(r));
          }, py::arg("client"), py::arg("regids"), py::keep_alive<0, 1>(),
          "A PollSource reading each register (3D REGID 00) every sample.");
    py::class_<CaptureSource, poll::Source, std::shared_ptr<CaptureSource>>(
        m, "CaptureSource",
        "A PollSource taking the latest cyclic transmission of each register (columns: arrival ns, values).")
        .def_property_readonly("interval_ms", &CaptureSource::interval_ms)
        .def_property_readonly("max_age", [](const CaptureSource& s) { return s.max_age_ns() / 1e9; })
        .def("close", &CaptureSource::close, py::call_guard<py::gil_scoped_release>(),
             "Stops the cyclic transmissions this source started (idempotent).");
    m.def("capture_source", [regids_arg](Client& c, const std::vector<std::int64_t>& regids,
                                                int interval_ms, const py::object& max_age) {
              auto r = regids_arg(regids);
              const Nanos age = max_age.is_none() ? 0 : duration_arg(max_age, "max_age").count();
              auto* bus = &c.bus();
              py::gil_scoped_release nogil;
              return std::make_shared<CaptureSource>(c, *bus, std::move(r), interval_ms, age);
          }, py::arg("client"), py::arg("regids"), py::arg("interval_ms"), py::arg("max_age") = py::none(),
          py::keep_alive<0, 1>(),
          "Subscribes each register every interval_ms (unless it already transmits) and captures it; "
          "max_age (s, default 3 intervals + 2 ms): older data counts as stale.");
}

void bind_unitek(py::module_& m) {
    bind_unitek_errors_and_profile(m);
    bind_unitek_registers(m);
    bind_unitek_codec(m);
    bind_unitek_client(m);
    bind_unitek_sim(m);
    bind_unitek_poll(m);
}
