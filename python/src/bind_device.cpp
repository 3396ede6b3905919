// Bindings of device/: HID enumeration and profiles, the simulated and replay devices and
// the trace writer (gauss6._gauss6.device). The trace reader is pure Python
// (gauss6.trace), so that traces read without the extension too.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "gauss6/hid_device.h"
#include "gauss6/replay_device.h"
#include "gauss6/simulated_device.h"
#include "gauss6/trace.h"
#include "module.h"

namespace py = pybind11;

namespace gauss6::python {

namespace {

py::dict entry_dict(const HidDeviceEntry& e) {
  py::dict d;
  d["path"] = e.path;
  d["vendor_id"] = e.vendor_id;
  d["product_id"] = e.product_id;
  d["serial"] = e.serial;
  d["manufacturer"] = e.manufacturer;
  d["product"] = e.product;
  d["interface_number"] = e.interface_number;
  const HidProfile* p = find_hid_profile(e.vendor_id, e.product_id);
  d["profile"] = p ? py::cast(std::string(p->name)) : py::none();
  return d;
}

// HID enumeration and the known device profiles.
void bind_hid(py::module_& m) {
  m.def("list_hid_devices", [] {
    py::list out;
    for (const HidDeviceEntry& e : list_hid_devices(*make_hidapi_backend())) out.append(entry_dict(e));
    return out;
  }, "Every HID interface hidapi sees, as dicts (path, vendor_id, product_id, serial, manufacturer, "
     "product, interface_number, profile: the gauss6 profile name or None).");
  m.def("hid_profiles", [] {
    py::list out;
    for (const HidProfile& p : hid_profiles()) {
      py::dict d;
      d["vendor_id"] = p.vendor_id;
      d["product_id"] = p.product_id;
      d["name"] = p.name;
      d["layout"] = p.layout == HidReportLayout::kSplit ? "split" : "combined";
      d["num_buttons"] = p.num_buttons;
      d["full_scale"] = p.full_scale;
      d["renders_force"] = p.renders_force;
      out.append(d);
    }
    return out;
  }, "The known HID device profiles (the SpaceMouse family).");
}

// The simulated device, driven from Python in lockstep: read(t) then write(t, F).
void bind_simulated_device(py::module_& m) {
  py::class_<SimulatedDevice>(m, "SimulatedDevice")
      .def(py::init([](const std::string& script_json, double rate_hz, double max_force, double max_torque,
                       const std::string& origin) {
             // As run_scenario builds it: the handle's defaults, the scene's rate and limits.
             SimulatedHandleParams params;
             if (rate_hz > 0) params.rate_hz = rate_hz;
             if (max_force > 0) params.max_force = max_force;
             if (max_torque > 0) params.max_torque = max_torque;
             try {
               auto d = std::make_unique<SimulatedDevice>(hand_script_from_json(script_json, origin), params);
               d->reset(0);
               return d;
             } catch (const std::invalid_argument& e) {
               throw LoadError(origin, e.what());  // gauss6.LoadError, as every file's errors
             }
           }),
           py::arg("script_json"), py::arg("rate_hz") = 0.0, py::arg("max_force") = 0.0, py::arg("max_torque") = 0.0,
           py::arg("origin") = "script",
           "A simulated device from a JSON hand script: the default handle parameters, with the scene's rate and "
           "limits when given (> 0), reset at t = 0 as run_scenario does (ValueError on a bad script).")
      .def("reset", &SimulatedDevice::reset, py::arg("t0") = 0.0,
           "Put the handle on the hand at t0, at rest relative to it, with no force.")
      .def_property_readonly("end_time", [](const SimulatedDevice& d) {
             const HandScript& s = d.script();
             return s.end_time >= 0 ? s.end_time : s.keys.back().t;
           }, "s: read() reports 'ended' after it")
      .def_property_readonly("let_go_time", [](const SimulatedDevice& d) { return d.script().let_go_time; })
      .def_property_readonly("phases", [](const SimulatedDevice& d) {
             py::list out;
             for (const HandPhase& p : d.script().phases) out.append(py::make_tuple(p.name, p.start));
             return out;
           }, "the script's phases as (name, start) pairs")
      .def_property_readonly("max_force", [](const SimulatedDevice& d) { return d.info().max_force; })
      .def_property_readonly("max_torque", [](const SimulatedDevice& d) { return d.info().max_torque; })
      .def("read", [](SimulatedDevice& d, double t) {
             DeviceState st;
             d.read(t, &st);
             return py::make_tuple(Eigen::Vector3d(st.X_WH.p), quat_to(st.X_WH.q), st.gripped, to_string(st.status));
           }, py::arg("t"), "Advance to t (s): returns (p, q, gripped, status).")
      .def("write", [](SimulatedDevice& d, double t, const Vec6& F) { return std::string(to_string(d.write(t, F))); },
           py::arg("t"), py::arg("F"), "Hold the wrench F = (force, torque) until the next write.")
      .def_property_readonly("rate_hz", [](const SimulatedDevice& d) { return d.info().rate_hz; });
}

// The replay device, driven from Python: the handle poses of a trace's ticks, played back.
void bind_replay_device(py::module_& m) {
  py::class_<ReplayDevice>(m, "ReplayDevice")
      .def(py::init([](const std::string& trace_path) {
             return std::make_unique<ReplayDevice>(ReplayDevice::from_trace(read_trace(trace_path),
                                                                            "replay: " + trace_path));
           }),
           py::arg("trace"), "The replay device of a trace file's ticks. Raises LoadError for a bad trace and "
                             "ValueError for times that do not increase or invalid poses.")
      .def("read", [](ReplayDevice& d, double t) {
             DeviceState st;
             d.read(t, &st);
             return py::make_tuple(Eigen::Vector3d(st.X_WH.p), quat_to(st.X_WH.q), st.gripped, st.buttons,
                                   to_string(st.status));
           }, py::arg("t"), "The handle at t (s): returns (p, q, gripped, buttons, status).")
      .def("write", [](ReplayDevice& d, double t, const Vec6& F) { return std::string(to_string(d.write(t, F))); },
           py::arg("t"), py::arg("F"), "Keep the wrench F (sent nowhere: a replay renders no force).")
      .def_property_readonly("end_time", &ReplayDevice::end_time)
      .def_property_readonly("num_samples", &ReplayDevice::num_samples)
      .def_property_readonly("rate_hz", [](const ReplayDevice& d) { return d.info().rate_hz; })
      .def_property_readonly("name", [](const ReplayDevice& d) { return d.info().name; });
}

// The trace writer: ticks, steps, contacts and events appended, flushed by a thread or by hand.
void bind_trace_writer(py::module_& m) {
  py::class_<TraceWriter>(m, "TraceWriter")
      .def(py::init([](const std::string& path, const std::string& scene, const std::string& device, double rate_hz,
                       const std::vector<std::pair<std::string, double>>& phases, const std::string& extra_json,
                       bool background_thread, double flush_period) {
             TraceMeta meta;
             meta.scene = scene;
             meta.device = device;
             meta.device_rate_hz = rate_hz;
             for (const auto& [name, start] : phases) meta.phases.push_back({name, start});
             meta.extra_json = extra_json;
             TraceWriterSettings s;
             s.background_thread = background_thread;
             s.flush_period = flush_period;
             return std::make_unique<TraceWriter>(path, meta, s);
           }),
           py::arg("path"), py::arg("scene") = "", py::arg("device") = "", py::arg("rate_hz") = 0.0,
           py::arg("phases") = std::vector<std::pair<std::string, double>>{}, py::arg("extra_json") = "{}",
           py::arg("background_thread") = true, py::arg("flush_period") = 0.25)
      .def("append_tick",
           [](TraceWriter& w, double t, const Eigen::Vector3d& xh_p, const Eigen::Vector4d& xh_q,
              const Eigen::Vector3d& xs_p, const Eigen::Vector4d& xs_q, const Vec6& wrench, int num_contacts,
              double force_time, int status, uint32_t flags, uint32_t buttons) {
             TraceTick r;
             r.t = t;
             r.X_WH = {xh_p, quat_from(xh_q)};
             r.X_WS = {xs_p, quat_from(xs_q)};
             r.F = wrench;
             r.num_contacts = num_contacts;
             r.force_time = force_time;
             r.status = static_cast<DeviceStatus>(status);
             r.flags = flags;
             r.buttons = buttons;
             return w.append(r);
           },
           py::arg("t"), py::arg("xh_p"), py::arg("xh_q"), py::arg("xs_p"), py::arg("xs_q"), py::arg("wrench"),
           py::arg("num_contacts") = 0, py::arg("force_time") = 0.0, py::arg("status") = 0, py::arg("flags") = 0,
           py::arg("buttons") = 0)
      .def("append_step",
           [](TraceWriter& w, uint64_t step, double t, double update_time, int num_contacts, int status,
              double update_cpu_time) {
             return w.append(TraceStep{step, t, update_time, num_contacts, status, update_cpu_time});
           },
           py::arg("step"), py::arg("t"), py::arg("update_time"), py::arg("num_contacts"), py::arg("status") = 0,
           py::arg("update_cpu_time") = std::numeric_limits<double>::quiet_NaN())
      .def("append_contact",
           [](TraceWriter& w, uint64_t step, double t, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
              double separation) { return w.append(TraceContact{step, t, point, normal, separation}); },
           py::arg("step"), py::arg("t"), py::arg("point"), py::arg("normal"), py::arg("separation"))
      .def("append_event",
           [](TraceWriter& w, double t, uint32_t code, double value) {
             return w.append(TraceEvent{t, static_cast<TraceEventCode>(code), value});
           },
           py::arg("t"), py::arg("code"), py::arg("value") = 0.0)
      .def("flush", &TraceWriter::flush, py::call_guard<py::gil_scoped_release>())
      .def("close", &TraceWriter::close, py::call_guard<py::gil_scoped_release>())
      .def("stats", [](const TraceWriter& w) {
        const TraceWriterStats s = w.stats();
        py::dict d;
        d["written"] = s.written;
        d["dropped"] = s.dropped;
        d["num_flushes"] = s.num_flushes;
        d["num_chunks"] = s.num_chunks;
        return d;
      });
}

}  // namespace

void bind_device(py::module_& parent) {
  py::module_ m = parent.def_submodule("device", "Devices (simulated, HID) and the trace writer");
  // A trace file's errors are load-time errors: gauss6.device.TraceError is a gauss6.LoadError.
  py::register_exception<TraceError>(m, "TraceError", parent.attr("LoadError"));
  bind_hid(m);
  bind_simulated_device(m);
  bind_replay_device(m);
  bind_trace_writer(m);
}

}  // namespace gauss6::python
