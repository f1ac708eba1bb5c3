// The Python module tetcollapse._core (pybind11): NumPy arrays in, NumPy arrays out. The
// package tetcollapse (python/tetcollapse/__init__.py) wraps it with the meshio bridge.
// Option names are the command line's, with underscores.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <map>
#include <string>
#include <vector>

#include "tetcollapse/check.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/error.hpp"
#include "tetcollapse/fields.hpp"
#include "tetcollapse/improve.hpp"
#include "tetcollapse/io.hpp"

namespace py = pybind11;
using namespace tc;

namespace {

// A vector handed to NumPy without a copy: the array owns it through a capsule.
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owner->data(), free_when_done);
}

// The points and tets alone, unchecked but for their shapes (check() reads any mesh).
Mesh raw_mesh(const py::array_t<double, py::array::c_style | py::array::forcecast>& points,
              const py::array_t<int32_t, py::array::c_style | py::array::forcecast>& tets) {
  if (points.ndim() != 2 || points.shape(1) != 3) throw InputError("<points>", "points must be an (N, 3) array");
  if (tets.ndim() != 2 || tets.shape(1) != 4) throw InputError("<tets>", "tets must be an (M, 4) array");
  Mesh m;
  m.points.assign(points.data(), points.data() + points.size());
  m.tets.assign(tets.data(), tets.data() + tets.size());
  return m;
}

Mesh from_numpy(py::array_t<double, py::array::c_style | py::array::forcecast> points,
                py::array_t<int32_t, py::array::c_style | py::array::forcecast> tets, py::object labels,
                py::object vertex_fields) {
  Mesh m = raw_mesh(points, tets);
  if (!labels.is_none()) {
    auto l = py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(labels);
    if (!l || l.ndim() != 1 || l.shape(0) != tets.shape(0))
      throw InputError("<labels>", "labels must be one integer per tet");
    m.tet_labels.push_back({"label", std::vector<int32_t>(l.data(), l.data() + l.size())});
  }
  if (!vertex_fields.is_none())
    for (auto item : vertex_fields.cast<py::dict>()) {
      auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(item.second);
      if (!a || a.ndim() < 1 || a.ndim() > 2 || a.shape(0) != points.shape(0))
        throw InputError("<vertex_fields>", "field '" + py::str(item.first).cast<std::string>() +
                                                "' must have one value (or row) per vertex");
      m.vertex_fields.push_back(
          {py::str(item.first), a.ndim() == 2 ? int(a.shape(1)) : 1, std::vector<double>(a.data(), a.data() + a.size())});
    }
  validate_structure(m, "<arrays>");
  normalize_orientation(m, OrientationPolicy::Refuse);
  return m;
}

py::dict to_dict(Mesh&& m) {
  py::dict d;
  const py::ssize_t nv = m.num_vertices(), nt = m.num_tets();
  d["points"] = to_numpy(std::move(m.points), {nv, 3});
  d["tets"] = to_numpy(std::move(m.tets), {nt, 4});
  if (!m.tet_labels.empty()) d["labels"] = to_numpy(std::move(m.tet_labels[0].values), {nt});
  py::dict fields;
  for (Field& f : m.vertex_fields) {
    const int c = f.components;
    fields[py::str(f.name)] = c == 1 ? to_numpy(std::move(f.values), {nv}) : to_numpy(std::move(f.values), {nv, c});
  }
  d["vertex_fields"] = fields;
  return d;
}

CollapseOptions::Boundary boundary_of(const std::string& b) {
  if (b == "strict") return CollapseOptions::Strict;
  if (b == "features") return CollapseOptions::Features;
  if (b == "free") return CollapseOptions::Free;
  throw InputError("<boundary>", "boundary must be 'strict', 'features' or 'free', not '" + b + "'");
}

py::dict quality_dict(const QualitySummary& q) {
  py::dict d;
  d["tets"] = q.tets;
  d["min_dihedral_deg"] = q.min_dihedral_deg;
  d["median_dihedral_deg"] = q.median_dihedral_deg;
  d["below_10_deg"] = q.below_10_deg;
  d["below_13_deg"] = q.below_13_deg;
  return d;
}

// One context per device spec for the module's life: a new one per call would read every program
// from the disk cache again (a tenth of a second and more, which a C++ caller keeping its Context
// does not pay). Calls on one device take turns (a Context is not thread-safe). Never freed: the
// OpenCL runtime may be gone before static destructors run at exit.
struct DeviceSlot {
  std::mutex m;
  std::unique_ptr<Context> ctx;
};
DeviceSlot& device_slot(const std::string& spec) {
  static std::mutex registry;
  static auto* slots = new std::map<std::string, std::unique_ptr<DeviceSlot>>();
  std::lock_guard<std::mutex> lock(registry);
  std::unique_ptr<DeviceSlot>& s = (*slots)[spec];
  if (!s) s = std::make_unique<DeviceSlot>();
  return *s;
}
// f(ctx) with the device's context, its turn taken.
template <class F>
auto on_device(const std::string& spec, F&& f) {
  DeviceSlot& slot = device_slot(spec);
  std::lock_guard<std::mutex> lock(slot.m);
  if (!slot.ctx) slot.ctx = std::make_unique<Context>(spec);
  return f(*slot.ctx);
}

py::dict collapse_py(py::array_t<double, py::array::c_style | py::array::forcecast> points,
                     py::array_t<int32_t, py::array::c_style | py::array::forcecast> tets, double target_factor,
                     py::object target_length, const std::string& boundary, py::object labels,
                     py::object vertex_fields, py::object device, const std::string& method, bool improve_phase,
                     double min_quality, py::object max_boundary_error, bool average_fields,
                     const std::string& preserve_field, double field_tolerance, double field_check,
                     double max_field_error,
                     const std::string& sizing_field, int cycles) {
  Mesh mesh = from_numpy(points, tets, labels, vertex_fields);
  CoarsenOptions co;
  CollapseOptions& o = co.collapse;
  o.target_factor = target_factor;
  if (!target_length.is_none()) o.target_length = target_length.cast<double>();
  o.boundary = boundary_of(boundary);
  o.min_quality = min_quality;
  // the command line's default: a bound in features mode unless one is given (None)
  o.max_boundary_error =
      !max_boundary_error.is_none() ? max_boundary_error.cast<double>() : default_max_boundary_error(o.boundary);
  o.max_field_error = max_field_error;
  co.improve = improve_phase;
  co.cycles = cycles;
  co.resample_fields = !average_fields;
  co.preserve_field = preserve_field;
  co.field_tolerance = field_tolerance;
  co.field_check = field_check;
  co.sizing_field = sizing_field;
  if (method != "parallel" && method != "sequential")
    throw InputError("<method>", "method must be 'parallel' or 'sequential', not '" + method + "'");
  const std::string spec = device.is_none() ? std::string() : device.cast<std::string>();
  CoarsenReport cr;
  {
    py::gil_scoped_release release;
    if (method == "sequential") {
      o.method = CollapseOptions::Sequential;
      cr = coarsen(mesh, co, nullptr);
    } else {
      cr = on_device(spec, [&](Context& ctx) { return coarsen(mesh, co, &ctx); });
    }
  }
  const CollapseReport& r = cr.collapse;
  const ImproveReport& ir = cr.improvement;
  improve_phase = cr.improved;
  py::dict stats;
  stats["vertices_in"] = r.vertices_in;
  stats["tets_in"] = r.tets_in;
  stats["vertices_out"] = mesh.num_vertices();
  stats["tets_out"] = mesh.num_tets();
  stats["iterations"] = r.iterations.size();
  stats["target_length"] = r.target_length;
  stats["device"] = r.device;
  stats["seconds_collapse"] = r.seconds_total;
  stats["boundary_error_bound"] = r.boundary_error_bound;
  stats["boundary_error"] = r.boundary_error;
  stats["field_error_bound"] = r.field_error_bound;
  stats["field_error"] = r.field_error;
  stats["cycles"] = 1 + cr.later_cycles.size();
  if (improve_phase) {
    stats["seconds_improve"] = ir.seconds_total;
    stats["quality_before_improve"] = quality_dict(ir.before);
    stats["quality"] = quality_dict(last_improvement(cr).after);
  } else {
    stats["quality"] = quality_dict(quality_summary(mesh));
  }
  py::dict d = to_dict(std::move(mesh));
  d["stats"] = stats;
  return d;
}

py::dict improve_py(py::array_t<double, py::array::c_style | py::array::forcecast> points,
                    py::array_t<int32_t, py::array::c_style | py::array::forcecast> tets, const std::string& boundary,
                    py::object labels, py::object vertex_fields, py::object device, const std::string& method) {
  Mesh mesh = from_numpy(points, tets, labels, vertex_fields);
  Mesh input;
  if (!mesh.vertex_fields.empty()) input = mesh;
  ImproveOptions io;
  io.boundary = boundary_of(boundary);
  ImproveReport ir;
  const std::string spec = device.is_none() ? std::string() : device.cast<std::string>();
  {
    py::gil_scoped_release release;
    if (method == "sequential") {
      ir = improve(mesh, io);
    } else {
      ir = on_device(spec, [&](Context& ctx) { return improve(mesh, io, ctx); });
    }
    if (!mesh.vertex_fields.empty()) resample_vertex_fields(input, mesh);
  }
  py::dict stats;
  stats["seconds_improve"] = ir.seconds_total;
  stats["quality_before"] = quality_dict(ir.before);
  stats["quality"] = quality_dict(ir.after);
  py::dict d = to_dict(std::move(mesh));
  d["stats"] = stats;
  return d;
}

py::dict check_py(py::array_t<double, py::array::c_style | py::array::forcecast> points,
                  py::array_t<int32_t, py::array::c_style | py::array::forcecast> tets) {
  const CheckReport r = check_mesh(raw_mesh(points, tets), {}, nullptr);
  py::module_ json = py::module_::import("json");
  return json.attr("loads")(check_report_json(r)).cast<py::dict>();
}

}  // namespace

PYBIND11_MODULE(_core, mod) {
  mod.doc() = "tetcollapse: coarsening of tetrahedral meshes by parallel edge collapse (C++ core)";
  static py::exception<DeviceError> device_error(mod, "DeviceError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const DeviceError& e) {
      device_error(e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  mod.def("collapse", &collapse_py, py::arg("points"), py::arg("tets"), py::kw_only(), py::arg("target_factor") = 1.0,
          py::arg("target_length") = py::none(), py::arg("boundary") = "features", py::arg("labels") = py::none(),
          py::arg("vertex_fields") = py::none(), py::arg("device") = py::none(), py::arg("method") = "parallel",
          py::arg("improve") = true, py::arg("min_quality") = 0.1, py::arg("max_boundary_error") = py::none(),
          py::arg("average_fields") = false, py::arg("preserve_field") = "", py::arg("field_tolerance") = 0.02,
          py::arg("field_check") = CoarsenOptions{}.field_check, py::arg("max_field_error") = 0.0, py::arg("sizing_field") = "",
          py::arg("cycles") = CoarsenOptions{}.cycles,
          "Coarsens a tet mesh; returns a dict: points, tets, labels (if given), vertex_fields, stats.");
  mod.def("improve", &improve_py, py::arg("points"), py::arg("tets"), py::kw_only(), py::arg("boundary") = "features",
          py::arg("labels") = py::none(), py::arg("vertex_fields") = py::none(), py::arg("device") = py::none(),
          py::arg("method") = "parallel", "Raises the worst element quality; returns a dict as collapse does.");
  // a first run's kernels compile in helper processes: this module, in another interpreter
  // (tetcollapse/__init__.py sets the command; tc::set_compile_helper)
  mod.def("_set_compile_helper", &tc::set_compile_helper, py::arg("argv"));
  mod.def("_compile_helper", &tc::run_compile_helper, py::arg("device_index"));
  mod.def("check", &check_py, py::arg("points"), py::arg("tets"),
          "Checks a mesh (tetcollapse check): the report as a dict (valid, findings, quality, ...).");
  mod.def(
      "read",
      [](const std::string& path) {
        Mesh m = read_mesh(path);
        return to_dict(std::move(m));
      },
      py::arg("path"), "Reads a mesh file (msh, mesh, meshb, vtk, vtu, node): a dict of arrays.");
  mod.def(
      "write",
      [](const std::string& path, py::array_t<double, py::array::c_style | py::array::forcecast> points,
         py::array_t<int32_t, py::array::c_style | py::array::forcecast> tets, py::object labels,
         py::object vertex_fields) { write_mesh(path, from_numpy(points, tets, labels, vertex_fields)); },
      py::arg("path"), py::arg("points"), py::arg("tets"), py::kw_only(), py::arg("labels") = py::none(),
      py::arg("vertex_fields") = py::none(), "Writes a mesh file (the format from the extension).");
  mod.def(
      "devices",
      [] {
        py::list out;
        for (const DeviceInfo& d : list_devices()) {
          py::dict e;
          e["index"] = d.index;
          e["name"] = d.name;
          e["platform"] = d.platform_name;
          e["type"] = d.type;
          e["compute_units"] = d.compute_units;
          e["fp64"] = d.fp64;
          out.append(e);
        }
        return out;
      },
      "The OpenCL devices (as `tetcollapse devices`).");
  mod.attr("__version__") = TETCOLLAPSE_VERSION;
}
