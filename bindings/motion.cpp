// Bindings for cpp/motorbus/motion: planners, profiles, drive profile models,
// StepNLoop, the motor model and homing.  Thin: conversions only; the Python
// conveniences live in python/motorbus/motion.py.
#include <pybind11/eigen.h>
#include <pybind11/eval.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "motorbus/motion/arcus_profile.hpp"
#include "motorbus/motion/dmac_profile.hpp"
#include "motorbus/motion/homing.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/motion/planner.hpp"
#include "motorbus/motion/stepnloop.hpp"
#include "motorbus/motion/steps.hpp"

namespace py = pybind11;
using namespace motorbus;
using namespace motorbus::motion;

namespace {
py::handle g_limit_exceeded;

py::tuple state_tuple(const State& s) { return py::make_tuple(s.p, s.v, s.a, s.j); }

py::array_t<double> vec_to_array(const std::vector<double>& v) {
    py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}
}  // namespace

void bind_motion(py::module_& m) {
    // ---- errors ----------------------------------------------------------------
    py::dict ns;
    ns["InvalidArgument"] = m.attr("InvalidArgument");
    py::exec(R"(
class LimitExceeded(InvalidArgument):
    "A motion request beyond a limit: .limit names it, .requested/.allowed/.excess quantify it."
    limit = ""
    requested = 0.0
    allowed = 0.0
    excess = 0.0
)", ns, ns);
    py::object le = ns["LimitExceeded"];
    le.attr("__module__") = "motorbus";
    m.attr("LimitExceeded") = le;
    g_limit_exceeded = le.release();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const LimitExceeded& e) {
            py::object exc = py::reinterpret_borrow<py::object>(g_limit_exceeded)(e.what());
            exc.attr("limit") = e.limit;
            exc.attr("requested") = e.requested;
            exc.attr("allowed") = e.allowed;
            exc.attr("excess") = e.excess();
            PyErr_SetObject(g_limit_exceeded.ptr(), exc.ptr());
        }
    });

    // ---- profiles and planners -------------------------------------------------
    py::class_<State>(m, "MotionState")
        .def(py::init([](double p, double v, double a, double j) { return State{p, v, a, j}; }), py::arg("p") = 0.0,
             py::arg("v") = 0.0, py::arg("a") = 0.0, py::arg("j") = 0.0)
        .def_readwrite("p", &State::p)
        .def_readwrite("v", &State::v)
        .def_readwrite("a", &State::a)
        .def_readwrite("j", &State::j)
        .def("__repr__", [](const State& s) {
            return "MotionState(p=" + std::to_string(s.p) + ", v=" + std::to_string(s.v) +
                   ", a=" + std::to_string(s.a) + ", j=" + std::to_string(s.j) + ")";
        });
    py::class_<Limits>(m, "Limits")
        .def(py::init([](double v, double a, double d, double j) { return Limits{v, a, d, j}; }),
             py::arg("max_velocity"), py::arg("max_acceleration"), py::arg("max_deceleration") = 0.0,
             py::arg("max_jerk") = 0.0)
        .def_readwrite("max_velocity", &Limits::max_velocity)
        .def_readwrite("max_acceleration", &Limits::max_acceleration)
        .def_readwrite("max_deceleration", &Limits::max_deceleration)
        .def_readwrite("max_jerk", &Limits::max_jerk);
    py::enum_<RampShape>(m, "RampShape")
        .value("TRAPEZOID", RampShape::Trapezoid)
        .value("SCURVE", RampShape::SCurve);

    py::class_<Profile>(m, "Profile", "A planned motion: position/velocity/acceleration/jerk at any time.")
        .def_property_readonly("duration", &Profile::duration)
        .def_property_readonly("start_position", &Profile::start_position)
        .def_property_readonly("end_position", &Profile::end_position)
        .def_property_readonly("final_velocity", [](const Profile& p) { return p.final_state().v; })
        .def_property_readonly("segment_count", [](const Profile& p) { return p.segments().size(); })
        .def("at", [](const Profile& p, double t) { return state_tuple(p.at(t)); }, py::arg("t"),
             "(p, v, a, j) at time t (s).")
        .def("position", &Profile::position, py::arg("t"))
        .def("velocity", &Profile::velocity, py::arg("t"))
        .def("acceleration", &Profile::acceleration, py::arg("t"))
        .def("jerk", &Profile::jerk, py::arg("t"))
        .def("sample", &Profile::sample, py::arg("n"), "n x 5 array: t, p, v, a, j over [0, duration].")
        .def("sample_at", &Profile::sample_at, py::arg("t"))
        .def("first_crossing", &Profile::first_crossing, py::arg("level"), py::arg("t_from") = 0.0)
        .def("max_abs_velocity", &Profile::max_abs_velocity)
        .def("max_abs_acceleration", &Profile::max_abs_acceleration)
        .def("max_abs_jerk", &Profile::max_abs_jerk)
        .def("segments",
             [](const Profile& p) {
                 py::list out;
                 for (const auto& s : p.segments())
                     out.append(py::make_tuple(s.t0, s.duration, state_tuple(s.start),
                                               s.kind == Segment::Kind::Cubic ? "cubic" : "exp"));
                 return out;
             })
        .def("step_times",
             [](const Profile& p, Nanos t0, std::size_t max_steps) {
                 StepTimes st;
                 {
                     py::gil_scoped_release rel;
                     st = step_times(p, t0, max_steps);
                 }
                 py::array_t<std::int64_t> t(static_cast<py::ssize_t>(st.size()));
                 py::array_t<std::int8_t> d(static_cast<py::ssize_t>(st.size()));
                 std::copy(st.t_ns.begin(), st.t_ns.end(), t.mutable_data());
                 std::copy(st.dir.begin(), st.dir.end(), d.mutable_data());
                 return py::make_tuple(t, d);
             },
             py::arg("t0_ns") = 0, py::arg("max_steps") = 100'000'000,
             "Integer step times (ns, int64) and directions (int8) for positions in steps.")
        .def("step_times_seconds",
             [](const Profile& p, std::size_t max_steps) { return vec_to_array(step_times_seconds(p, max_steps)); },
             py::arg("max_steps") = 100'000'000);

    m.def("plan_trapezoid", &plan_trapezoid, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("plan_velocity", &plan_velocity, py::arg("start"), py::arg("target_velocity"), py::arg("limits"),
          py::arg("hold") = 0.0, py::arg("shape") = RampShape::Trapezoid);
    m.def("plan_jerk_limited", &plan_jerk_limited, py::arg("start"), py::arg("target"), py::arg("limits"));
    m.def("plan_synchronized", &plan_synchronized, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("plan_straight_line", &plan_straight_line, py::arg("start"), py::arg("target"), py::arg("limits"),
          py::arg("shape") = RampShape::Trapezoid);
    m.def("split_interpolation", &split_interpolation, py::arg("axes"), py::arg("period_ms"));
    m.def(
        "jerk_limited_durations",
        [](py::array_t<double, py::array::c_style | py::array::forcecast> cases) {
            // Batch duration query (rows: p0, v0, a0, target, vmax, amax, jmax) for
            // interop tests and benchmarks without per-call Python overhead.
            if (cases.ndim() != 2 || cases.shape(1) != 7) throw InvalidArgument("cases must be N x 7");
            const auto n = cases.shape(0);
            py::array_t<double> out(n);
            auto c = cases.unchecked<2>();
            double* o = out.mutable_data();
            for (py::ssize_t i = 0; i < n; ++i) {
                Limits lim{c(i, 4), c(i, 5), 0, c(i, 6)};
                o[i] = plan_jerk_limited(State{c(i, 0), c(i, 1), c(i, 2), 0}, c(i, 3), lim).duration();
            }
            return out;
        },
        py::arg("cases"));

    // ---- Arcus -----------------------------------------------------------------
    py::class_<ArcusSpeedWindow>(m, "ArcusSpeedWindow")
        .def_readonly("number", &ArcusSpeedWindow::number)
        .def_readonly("sspdm_first", &ArcusSpeedWindow::sspdm_first)
        .def_readonly("sspdm_last", &ArcusSpeedWindow::sspdm_last)
        .def_readonly("hspd_low", &ArcusSpeedWindow::hspd_low)
        .def_readonly("hspd_high", &ArcusSpeedWindow::hspd_high)
        .def_readonly("min_lspd", &ArcusSpeedWindow::min_lspd)
        .def_readonly("min_acc_ms", &ArcusSpeedWindow::min_acc_ms)
        .def_readonly("delta", &ArcusSpeedWindow::delta);
    m.def("arcus_speed_windows", [] {
        const auto& w = arcus_speed_windows();
        return std::vector<ArcusSpeedWindow>(w.begin(), w.end());
    });
    m.def("arcus_window_for_hspd", &arcus_window_for_hspd, py::arg("hspd_pps"), py::return_value_policy::copy);
    m.def("arcus_window_for_sspdm", &arcus_window_for_sspdm, py::arg("sspdm"), py::return_value_policy::copy);
    m.def("arcus_max_acc_ms", &arcus_max_acc_ms, py::arg("hspd_pps"), py::arg("lspd_pps"));
    py::class_<ArcusProfileParams>(m, "ArcusProfileParams")
        .def(py::init([](double hspd, double lspd, double acc_ms, double dec_ms, bool edec, bool scv, double ratio) {
                 return ArcusProfileParams{hspd, lspd, acc_ms, dec_ms, edec, scv, ratio};
             }),
             py::arg("hspd") = 1000.0, py::arg("lspd") = 100.0, py::arg("acc_ms") = 300.0, py::arg("dec_ms") = 300.0,
             py::arg("edec") = false, py::arg("scv") = false, py::arg("snl_ratio") = 1.0)
        .def_readwrite("hspd", &ArcusProfileParams::hspd)
        .def_readwrite("lspd", &ArcusProfileParams::lspd)
        .def_readwrite("acc_ms", &ArcusProfileParams::acc_ms)
        .def_readwrite("dec_ms", &ArcusProfileParams::dec_ms)
        .def_readwrite("edec", &ArcusProfileParams::edec)
        .def_readwrite("scv", &ArcusProfileParams::scv)
        .def_readwrite("snl_ratio", &ArcusProfileParams::snl_ratio);
    m.def("arcus_effective", [](const ArcusProfileParams& p) {
        auto e = arcus_effective(p);
        return py::make_tuple(e.params, e.window ? e.window->number : 0, e.adjustments);
    }, py::arg("params"), "(effective params, window number, [adjustments]) after Appendix A.");
    m.def("arcus_check_strict", &arcus_check_strict, py::arg("params"));
    m.attr("ARCUS_MAX_MOVE_DISTANCE") = kArcusMaxMoveDistance;
    py::class_<ArcusMotion>(m, "ArcusMotion")
        .def(py::init<ArcusProfileParams, int>(), py::arg("params") = ArcusProfileParams{}, py::arg("sspdm") = 0)
        .def("set_params", [](ArcusMotion& a, const ArcusProfileParams& p) { return a.set_params(p).params; })
        .def("set_sspdm", &ArcusMotion::set_sspdm)
        .def_property_readonly("effective", [](const ArcusMotion& a) { return a.effective().params; })
        .def("move", [](ArcusMotion& a, double pos, double target) { return arcus_reply_text(a.move(pos, target)); },
             py::arg("position"), py::arg("target"), "X: returns '' or the drive's error reply.")
        .def("jog", [](ArcusMotion& a, double pos, int dir) { return arcus_reply_text(a.jog(pos, dir)); })
        .def("change_target",
             [](ArcusMotion& a, double t, double target) { return arcus_reply_text(a.change_target(t, target)); },
             py::arg("t"), py::arg("target"))
        .def("change_speed",
             [](ArcusMotion& a, double t, double v) { return arcus_reply_text(a.change_speed(t, v)); },
             py::arg("t"), py::arg("hspd"))
        .def("stop", &ArcusMotion::stop, py::arg("t"))
        .def("abort", &ArcusMotion::abort, py::arg("t"))
        .def_property_readonly("profile", &ArcusMotion::profile, py::return_value_policy::copy)
        .def("moving", &ArcusMotion::moving, py::arg("t"))
        .def("phase", [](const ArcusMotion& a, double t) {
            switch (a.phase(t)) {
                case ArcusPhase::Accel: return "accel";
                case ArcusPhase::Const: return "const";
                case ArcusPhase::Decel: return "decel";
                default: return "idle";
            }
        }, py::arg("t"));

    // ---- DMAC ------------------------------------------------------------------
    py::class_<DmacProfileParams>(m, "DmacProfileParams")
        .def(py::init([](std::int32_t hs, std::int32_t ls, std::int32_t ati, std::int32_t dti, bool sc) {
                 DmacProfileParams p{hs, ls, ati, dti, sc};
                 p.validate();
                 return p;
             }),
             py::arg("high_speed") = 60000, py::arg("low_speed") = 6000, py::arg("accel_time_ms") = 1000,
             py::arg("decel_time_ms") = 1000, py::arg("s_curve") = false)
        .def_readwrite("high_speed", &DmacProfileParams::high_speed)
        .def_readwrite("low_speed", &DmacProfileParams::low_speed)
        .def_readwrite("accel_time_ms", &DmacProfileParams::accel_time_ms)
        .def_readwrite("decel_time_ms", &DmacProfileParams::decel_time_ms)
        .def_readwrite("s_curve", &DmacProfileParams::s_curve);
    m.def("dmac_ramp_time", &dmac_ramp_time, py::arg("params"), py::arg("v_from"), py::arg("v_to"));
    m.def("dmac_position_profile", &dmac_position_profile, py::arg("start"), py::arg("target"), py::arg("params"));
    m.def("dmac_speed_profile", &dmac_speed_profile, py::arg("start"), py::arg("speed"), py::arg("params"),
          py::arg("hold") = 0.0);
    py::class_<DmacMotion>(m, "DmacMotion")
        .def(py::init<DmacProfileParams, double>(), py::arg("params") = DmacProfileParams{}, py::arg("position") = 0.0)
        .def("set_params", &DmacMotion::set_params)
        .def("move_to", &DmacMotion::move_to, py::arg("t"), py::arg("target"))
        .def("move_on", &DmacMotion::move_on, py::arg("t"), py::arg("offset"))
        .def("move_speed", &DmacMotion::move_speed, py::arg("t"), py::arg("speed"))
        .def("stop", &DmacMotion::stop, py::arg("t"))
        .def_property_readonly("profile", &DmacMotion::profile, py::return_value_policy::copy)
        .def("moving", &DmacMotion::moving, py::arg("t"));

    // ---- StepNLoop -------------------------------------------------------------
    py::class_<SnlConfig>(m, "SnlConfig")
        .def(py::init<>())
        .def_readwrite("enabled", &SnlConfig::enabled)
        .def_readwrite("tolerance", &SnlConfig::tolerance)
        .def_readwrite("error_range", &SnlConfig::error_range)
        .def_readwrite("max_attempts", &SnlConfig::max_attempts)
        .def_readwrite("idle_tolerance", &SnlConfig::idle_tolerance)
        .def_readwrite("ratio", &SnlConfig::ratio);
    py::class_<StepNLoop>(m, "StepNLoop")
        .def(py::init<SnlConfig>(), py::arg("config") = SnlConfig{})
        .def("configure", &StepNLoop::configure)
        .def("begin", [](StepNLoop& s, const std::string& what) {
            static const std::pair<const char*, SnlActivity> map[] = {
                {"move", SnlActivity::Move}, {"jog", SnlActivity::Jog}, {"home", SnlActivity::Home},
                {"zhome", SnlActivity::ZHome}, {"limit_home", SnlActivity::LimitHome},
                {"stop", SnlActivity::Stop}, {"abort", SnlActivity::Abort}};
            for (const auto& [n, a] : map)
                if (what == n) return s.begin(a);
            throw InvalidArgument("StepNLoop.begin: unknown activity '" + what + "'");
        }, py::arg("activity"))
        .def("monitor", [](StepNLoop& s, double d) { auto r = s.monitor(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("motion_done", [](StepNLoop& s, double d) { auto r = s.motion_done(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("idle_check", [](StepNLoop& s, double d) { auto r = s.idle_check(d); return py::make_tuple(static_cast<int>(r.action), r.correction, r.idle_current); })
        .def("limit_hit", &StepNLoop::limit_hit)
        .def("clear", &StepNLoop::clear)
        .def_property_readonly("status", [](const StepNLoop& s) { return static_cast<int>(s.status()); })
        .def_property_readonly("status_name", [](const StepNLoop& s) { return snl_status_name(s.status()); })
        .def_property_readonly("attempts", &StepNLoop::attempts);
}
