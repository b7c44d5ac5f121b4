// The Python module `oocsimp`: numpy arrays and files in, through the library's facade
// (oocsimp/oocsimp.hpp) only. docs/python.md documents every function with an example.
//
// The GIL is released while the library works; its progress callback, on the calling
// thread, takes the GIL back briefly to let Python run its signal handlers, so Ctrl-C
// cancels a run (KeyboardInterrupt) with its temporary files deleted.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "oocsimp/error.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace {

// The library names an option by its field; Python shows the keyword that sets it.
constexpr std::pair<const char*, const char*> kKeywordOfField[] = {
    {"options.target.triangles", "target_tris"},
    {"options.target.ratio", "target_ratio"},
    {"options.target.max_error", "max_error"},
    {"options.sizing.cell", "cell"},
    {"options.sizing.grid", "grid"},
    {"options.sizing.ratio", "ratio"},
    {"options.memory_budget", "mem"},
    {"options.attributes", "attributes"},
    {"options.temp_dir", "tmp"},
    {"options.thick_edges", "thick_edges"},
    {"options.lock_boundary", "lock_boundary"},
    {"options.locked_vertices", "locked"},
    {"options.method", "method"},
    {"options.samples", "samples"},
    {"outputs.mesh", "output"},
    {"outputs.stats", "stats"},
};

// `message` with every library field replaced by its keyword.
std::string with_keywords(std::string message) {
  for (const auto& [field, keyword] : kKeywordOfField)
    for (std::size_t at = message.find(field); at != std::string::npos; at = message.find(field, at))
      message.replace(at, std::string(field).size(), keyword);
  return message;
}

// A progress callback that lets Python's signal handlers run, on the thread that
// called in (Python handles signals there only): a handler that raises (Ctrl-C's
// KeyboardInterrupt) cancels the run.
oocsimp::ProgressCallback python_signals() {
  const std::thread::id caller = std::this_thread::get_id();
  return [caller](const oocsimp::Progress&) {
    if (std::this_thread::get_id() != caller) return true;
    py::gil_scoped_acquire gil;
    return PyErr_CheckSignals() == 0 && !PyErr_Occurred();
  };
}

// --- options

// A count given as a Python int; ValueError naming the keyword otherwise.
std::uint64_t whole_number(const char* keyword, const py::handle& value) {
  if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value))
    throw py::value_error(std::string(keyword) + " must be a whole number, not " +
                          std::string(py::str(py::type::of(value).attr("__name__"))));
  const long long v = value.cast<long long>();
  if (v < 0) throw py::value_error(std::string(keyword) + " must not be negative: " + std::to_string(v));
  return std::uint64_t(v);
}

double real_number(const char* keyword, const py::handle& value) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)))
    throw py::value_error(std::string(keyword) + " must be a number");
  return value.cast<double>();
}

template <class E>
E enum_value(const char* keyword, const oocsimp::EnumNames<E>& names, const py::handle& value) {
  E e{};
  const std::string text = py::str(value);
  if (oocsimp::value_named(names, text, &e)) return e;
  std::string known;
  for (const auto& n : names) known += std::string(known.empty() ? "" : ", ") + n.name;
  throw py::value_error(std::string(keyword) + " must be one of " + known + ", not \"" + text + "\"");
}

// locked=: vertex indices, or a boolean mask with a value per vertex.
std::vector<std::uint64_t> vertex_list(const py::handle& value) {
  py::array a = py::array::ensure(value);
  if (!a || a.ndim() != 1) throw py::value_error("locked must be a 1-d array of vertex indices or a boolean mask");
  std::vector<std::uint64_t> out;
  if (a.dtype().kind() == 'b') {
    auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(a).unchecked<1>();
    for (py::ssize_t i = 0; i < mask.shape(0); ++i)
      if (mask(i)) out.push_back(std::uint64_t(i));
    return out;
  }
  if (a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
    throw py::value_error("locked must hold integers or booleans");
  auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a).unchecked<1>();
  for (py::ssize_t i = 0; i < idx.shape(0); ++i) {
    if (idx(i) < 0)
      throw py::value_error("locked[" + std::to_string(i) + "] = " + std::to_string(idx(i)) + " is no vertex");
    out.push_back(std::uint64_t(idx(i)));
  }
  return out;
}

// max_error=: a length in model units, or a string "0.1%", a percentage of the input's
// bounding-box diagonal.
void set_max_error(const py::handle& value, oocsimp::TargetOptions* target) {
  if (!py::isinstance<py::str>(value)) {
    target->max_error = real_number("max_error", value);
    if (!(target->max_error > 0 && std::isfinite(target->max_error)))
      throw py::value_error("max_error must be above 0, not " + std::string(py::str(value)));
    return;
  }
  const std::string text = value.cast<std::string>();
  char* end = nullptr;
  const double percent = std::strtod(text.c_str(), &end);
  if (text.empty() || text.back() != '%' || end != text.c_str() + text.size() - 1 || !(percent > 0 && percent <= 100))
    throw py::value_error(
        "max_error must be a length in model units or a percentage of the diagonal such as "
        "\"0.1%\", not \"" +
        text + "\"");
  target->max_error_of_diagonal = percent / 100;
}

// The keywords simplify() and simplify_file() share, into `o`; each one used is
// removed from `kw`, so that what is left is unknown.
void read_options(py::dict& kw, oocsimp::SimplifyOptions* o) {
  auto take = [&kw](const char* key, py::object* value) {
    if (!kw.contains(key)) return false;
    *value = kw[key];
    PyDict_DelItemString(kw.ptr(), key);
    return !value->is_none();
  };
  py::object v;
  // A value the library reads as "not given" (0) would quietly run without the target
  // asked for: refused, as the command line refuses it.
  if (take("target_tris", &v)) {
    o->target.triangles = whole_number("target_tris", v);
    if (o->target.triangles < 4)
      throw py::value_error("target_tris must be at least 4, not " + std::to_string(o->target.triangles));
  }
  if (take("target_ratio", &v)) {
    o->target.ratio = real_number("target_ratio", v);
    if (!(o->target.ratio > 0 && o->target.ratio <= 1))
      throw py::value_error("target_ratio must be above 0 and at most 1, not " + std::string(py::str(v)));
  }
  if (take("max_error", &v)) set_max_error(v, &o->target);
  if (take("method", &v)) o->method = enum_value("method", oocsimp::cluster_method_names(), v);
  if (take("grid", &v)) {
    o->sizing.grid = std::uint32_t(whole_number("grid", v));
    if (o->sizing.grid == 0) throw py::value_error("grid must be at least 1, not 0");
  }
  if (take("cell", &v)) {
    o->sizing.cell = real_number("cell", v);
    if (!(o->sizing.cell > 0)) throw py::value_error("cell must be above 0, not " + std::string(py::str(v)));
  }
  if (take("ratio", &v)) {
    o->sizing.ratio = real_number("ratio", v);
    if (!(o->sizing.ratio > 0)) throw py::value_error("ratio must be above 0, not " + std::string(py::str(v)));
  }
  if (take("mem", &v)) {
    if (!py::isinstance<py::str>(v)) {
      o->memory_budget = whole_number("mem", v);
    } else {
      try {
        o->memory_budget = oocsimp::parse_byte_size(v.cast<std::string>());
      } catch (const oocsimp::UsageError& e) {
        throw py::value_error(std::string("mem: ") + e.what());
      }
    }
  }
  if (take("threads", &v)) o->threads = unsigned(whole_number("threads", v));
  if (take("tmp", &v)) o->temp_dir = py::str(v);
  if (take("thick_edges", &v)) o->thick_edges = v.cast<bool>();
  if (take("lock_boundary", &v)) o->lock_boundary = v.cast<bool>();
  if (take("locked", &v)) o->locked_vertices = vertex_list(v);
  if (take("weld", &v)) o->weld = v.cast<bool>();
  if (take("precision", &v)) o->precision = enum_value("precision", oocsimp::precision_names(), v);
  if (take("refine", &v)) o->target.refine = enum_value("refine", oocsimp::refine_method_names(), v);
  if (take("attributes", &v)) o->attributes = oocsimp::parse_attribute_selection(py::str(v));
}

void refuse_unknown(const py::dict& kw, const char* function) {
  if (kw.empty()) return;
  throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" +
                       std::string(py::str(kw.begin()->first)) + "'");
}

// --- arrays

// A (count, width) array of numbers; `what` names it in errors.
py::array checked_rows(const char* what, const py::handle& value, py::ssize_t width, std::size_t count) {
  py::array a = py::array::ensure(value);
  if (!a) throw py::value_error(std::string(what) + " must be an array");
  if (a.ndim() != 2 || a.shape(1) != width)
    throw py::value_error(std::string(what) + " must have shape (n, " + std::to_string(width) + ")");
  if (count != std::size_t(-1) && std::size_t(a.shape(0)) != count)
    throw py::value_error(std::string(what) + " must have a row per vertex (" + std::to_string(count) + "), not " +
                          std::to_string(a.shape(0)));
  return a;
}

// Whether the library can read `a` in place: its rows' values adjacent, of a type it
// reads (else it is copied to `fallback`'s type).
template <class T>
py::array in_place_or_copy(py::array a) {
  if (a.dtype().is(py::dtype::of<T>()) && a.strides(1) == py::ssize_t(sizeof(T)) && a.strides(0) > 0) return a;
  return py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
}

oocsimp::AttributeType attribute_type_of(const py::array& a) {
  if (a.dtype().is(py::dtype::of<std::uint8_t>())) return oocsimp::AttributeType::u8;
  if (a.dtype().is(py::dtype::of<float>())) return oocsimp::AttributeType::f32;
  return oocsimp::AttributeType::f64;
}

// The vertex attributes simplify() carries: a named group of columns each.
struct AttributeGroup {
  const char* keyword;
  std::vector<const char*> names;  // the library's, per column
  py::array values;                // kept alive while the run reads them
};

// The group's columns as attributes of `view`.
void add_group(AttributeGroup& g, oocsimp::MeshView* view) {
  py::array& a = g.values;
  if (!(a.dtype().is(py::dtype::of<std::uint8_t>()) || a.dtype().is(py::dtype::of<float>())))
    a = in_place_or_copy<double>(a);
  else if (a.strides(1) != a.itemsize() || a.strides(0) <= 0)
    a = py::array::ensure(a, py::array::c_style);
  const oocsimp::AttributeType type = attribute_type_of(a);
  for (std::size_t k = 0; k < g.names.size(); ++k)
    view->attributes.add({g.names[k], type, 0, 0}, static_cast<const unsigned char*>(a.data()) + k * a.itemsize(),
                         std::size_t(a.strides(0)));
}

// The group's columns of `mesh` as an array of the type it came in.
py::array group_result(const AttributeGroup& g, const oocsimp::SimplifiedMesh& mesh) {
  const oocsimp::AttributeValues& attrs = mesh.attributes;
  const std::size_t width = attrs.attributes.size(), n = mesh.positions.size() / 3;
  std::vector<std::size_t> column;
  for (const char* name : g.names)
    for (std::size_t k = 0; k < width; ++k)
      if (attrs.attributes[k].name == name) column.push_back(k);
  const std::size_t m = column.size();
  py::array_t<double> out({n, m});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < m; ++k) o(i, k) = attrs.values[i * width + column[k]];
  if (std::string(g.keyword) == "normals")  // a cluster's mean of unit normals is shorter than one
    for (std::size_t i = 0; i < n; ++i) {
      const double l = std::sqrt(o(i, 0) * o(i, 0) + o(i, 1) * o(i, 1) + o(i, 2) * o(i, 2));
      if (l > 0)
        for (std::size_t k = 0; k < 3; ++k) o(i, k) /= l;
    }
  return out.attr("astype")(g.values.dtype());
}

// --- functions

// The run's warnings (what the output lost, an option that did nothing) as Python
// warnings, each naming keywords where the library names fields: the command line
// prints the same lines on stderr.
void warn_of(const oocsimp::SimplifyStats& stats) {
  for (const std::string& w : stats.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, with_keywords(w).c_str(), 1) != 0) throw py::error_already_set();
}

py::object simplify(py::array vertices, py::array faces, py::kwargs kwargs) {
  py::dict kw(kwargs);
  oocsimp::SimplifyOptions options;
  std::vector<AttributeGroup> groups;
  const std::size_t vertex_count = std::size_t(checked_rows("vertices", vertices, 3, std::size_t(-1)).shape(0));
  for (auto [keyword, names] : {std::pair<const char*, std::vector<const char*>>{"colors", {}},
                                {"normals", {"nx", "ny", "nz"}},
                                {"uvs", {"u", "v"}}}) {
    if (!kw.contains(keyword)) continue;
    py::object value = kw[keyword];
    PyDict_DelItemString(kw.ptr(), keyword);
    if (value.is_none()) continue;
    if (std::string(keyword) == "colors") {
      py::array a = py::array::ensure(value);
      const py::ssize_t width = a && a.ndim() == 2 ? a.shape(1) : 0;
      names = width == 4 ? std::vector<const char*>{"red", "green", "blue", "alpha"}
                         : std::vector<const char*>{"red", "green", "blue"};
    }
    groups.push_back({keyword, names, checked_rows(keyword, value, py::ssize_t(names.size()), vertex_count)});
  }
  read_options(kw, &options);
  refuse_unknown(kw, "simplify");
  for (const AttributeGroup& g : groups)
    if (std::string(g.keyword) == "uvs" && oocsimp::resolved_method(options) != oocsimp::ClusterMethod::qem)
      throw py::value_error(std::string("uvs need the edge collapse (a target, method qem): clustering by ") +
                            oocsimp::method_name(oocsimp::resolved_method(options)) +
                            " merges vertices across texture seams");

  const bool doubles = vertices.dtype().is(py::dtype::of<double>());
  py::array positions = doubles ? in_place_or_copy<double>(vertices) : in_place_or_copy<float>(vertices);
  py::array_t<std::uint32_t> indices;
  py::array f = checked_rows("faces", faces, 3, std::size_t(-1));
  if (f.dtype().kind() != 'i' && f.dtype().kind() != 'u') throw py::value_error("faces must hold integers");
  if ((f.dtype().is(py::dtype::of<std::int32_t>()) || f.dtype().is(py::dtype::of<std::uint32_t>())) &&
      f.strides(1) == 4 && f.strides(0) == 12) {
    indices = py::array_t<std::uint32_t>(f.attr("view")("uint32"));  // in place; the library checks the range
  } else {
    py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> wide(f);
    auto w = wide.unchecked<2>();
    indices = py::array_t<std::uint32_t>({std::size_t(w.shape(0)), std::size_t(3)});
    auto out = indices.mutable_unchecked<2>();
    for (py::ssize_t t = 0; t < w.shape(0); ++t)
      for (py::ssize_t k = 0; k < 3; ++k) {
        const std::int64_t i = w(t, k);
        if (i < 0 || std::uint64_t(i) >= vertex_count)
          throw py::value_error("faces[" + std::to_string(t) + ", " + std::to_string(k) + "] = " + std::to_string(i) +
                                " is no vertex (0 to " + std::to_string(vertex_count) + " - 1)");
        out(t, k) = std::uint32_t(i);
      }
  }

  oocsimp::MeshView view;
  view.positions = positions.data();
  view.position_type = doubles ? oocsimp::ScalarType::f64 : oocsimp::ScalarType::f32;
  view.position_stride = std::size_t(positions.strides(0));
  view.vertex_count = vertex_count;
  view.indices = indices.data();
  view.triangle_count = std::uint64_t(indices.shape(0));
  for (AttributeGroup& g : groups) add_group(g, &view);
  options.progress = python_signals();

  oocsimp::SimplifiedMesh mesh;
  oocsimp::SimplifyStats stats;
  {
    py::gil_scoped_release released;
    mesh = oocsimp::simplify_mesh(view, options, &stats);
  }
  warn_of(stats);
  const std::size_t n = mesh.positions.size() / 3, m = mesh.triangles.size() / 3;
  py::array_t<double> v({n, std::size_t(3)}, mesh.positions.data());
  py::array_t<std::uint32_t> t({m, std::size_t(3)}, mesh.triangles.data());
  py::object v_out = doubles ? py::object(v) : v.attr("astype")("float32");
  py::object f_out = t.attr("astype")(f.dtype());
  if (groups.empty()) return py::make_tuple(v_out, f_out);
  py::dict attributes;
  for (const AttributeGroup& g : groups) attributes[g.keyword] = group_result(g, mesh);
  return py::make_tuple(v_out, f_out, attributes);
}

py::object simplify_file(const std::string& input, const std::string& output, py::kwargs kwargs) {
  py::dict kw(kwargs);
  oocsimp::SimplifyOptions options;
  oocsimp::OutputOptions outputs;
  outputs.mesh = output;
  for (const char* key : {"ascii", "normals", "stats", "force"}) {
    if (!kw.contains(key)) continue;
    py::object v = kw[key];
    PyDict_DelItemString(kw.ptr(), key);
    if (v.is_none()) continue;
    const std::string k = key;
    if (k == "ascii") outputs.ascii = v.cast<bool>();
    if (k == "normals") outputs.normals = v.cast<bool>();
    if (k == "stats") outputs.stats = py::str(v);
    if (k == "force") outputs.replace_input = v.cast<bool>();
  }
  read_options(kw, &options);
  refuse_unknown(kw, "simplify_file");
  options.progress = python_signals();
  oocsimp::SimplifyStats stats;
  std::string json;
  {
    py::gil_scoped_release released;
    oocsimp::simplify_file(input, outputs, options, &stats);
    json = oocsimp::stats_to_json(stats, input, outputs, options);
  }
  warn_of(stats);
  return py::module_::import("json").attr("loads")(json);
}

// A mesh given to measure(): a path, or (vertices, faces) written to a PLY in `dir`.
std::string mesh_path(const py::handle& mesh, const std::string& dir, const char* name) {
  if (py::isinstance<py::str>(mesh) || py::hasattr(mesh, "__fspath__"))
    return py::str(py::module_::import("os").attr("fspath")(mesh));
  if (!py::isinstance<py::tuple>(mesh) || py::len(mesh) != 2)
    throw py::value_error(std::string(name) + " must be a path or a (vertices, faces) tuple");
  py::tuple pair = py::reinterpret_borrow<py::tuple>(mesh);
  py::array_t<double, py::array::c_style | py::array::forcecast> v(
      checked_rows("vertices", pair[0], 3, std::size_t(-1)));
  py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> f(
      checked_rows("faces", pair[1], 3, std::size_t(-1)));
  std::vector<double> positions(v.data(), v.data() + v.size());
  std::vector<std::uint32_t> triangles(std::size_t(f.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const std::int64_t x = f.data()[i];
    if (x < 0 || std::uint64_t(x) >= std::uint64_t(v.shape(0)))
      throw py::value_error(std::string(name) + ": faces hold " + std::to_string(x) + ", no vertex");
    triangles[i] = std::uint32_t(x);
  }
  const std::string path = dir + "/" + name + ".ply";
  oocsimp::write_mesh(path, positions, triangles, oocsimp::MeshFormat::ply_binary, oocsimp::ScalarType::f64);
  return path;
}

py::object measure(const py::object& a, const py::object& b, std::uint64_t samples, std::uint64_t seed,
                   std::optional<unsigned> threads, std::optional<std::string> tmp) {
  py::object tempfile = py::module_::import("tempfile");
  py::object scratch = tempfile.attr("TemporaryDirectory")("prefix"_a = "oocsimp-measure-");
  const std::string dir = py::str(scratch.attr("name"));
  oocsimp::MeasureOptions options;
  options.samples = samples;
  options.seed = seed;
  if (threads) options.threads = *threads;
  if (tmp) options.temp_dir = *tmp;
  options.progress = python_signals();
  const std::string a_path = mesh_path(a, dir, "a"), b_path = mesh_path(b, dir, "b");
  std::string json;
  {
    py::gil_scoped_release released;
    json = oocsimp::distance_report_to_json(oocsimp::measure_surface_distance(a_path, b_path, options));
  }
  scratch.attr("cleanup")();
  return py::module_::import("json").attr("loads")(json);
}

}  // namespace

PYBIND11_MODULE(oocsimp, m) {
  m.doc() = "Out-of-core simplification of triangle meshes (docs/python.md).";
  m.attr("__version__") = oocsimp::version();
  static py::exception<oocsimp::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const oocsimp::UsageError& e) {
      PyErr_SetString(PyExc_ValueError, with_keywords(e.what()).c_str());
    } catch (const oocsimp::InputError& e) {
      input_error(e.what());
    } catch (const oocsimp::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const oocsimp::Cancelled&) {
      if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
    }
  });
  m.def("simplify", &simplify, "vertices"_a, "faces"_a,
        "simplify(vertices, faces, target_tris=None, target_ratio=None, max_error=None, method=None, colors=None,\n"
        "         normals=None, threads=None, ...) -> (vertices, faces[, attributes])\n\n"
        "Simplifies a mesh held in numpy arrays: vertices (n, 3) float32 or float64, faces (m, 3) integers.\n"
        "colors (n, 3 or 4), normals (n, 3) and uvs (n, 2) are carried and returned in a dict; uvs need\n"
        "the edge collapse (a target), whose seams (vertices split at one position) stay where they are.\n"
        "The other keywords are simplify_file's.");
  m.def("simplify_file", &simplify_file, "input"_a, "output"_a,
        "simplify_file(input, output, **options) -> dict\n\n"
        "Simplifies the mesh file `input` into `output`, as `oocsimp simplify` does with the same options\n"
        "(the same bytes), and returns the run's statistics.");
  m.def("measure", &measure, "a"_a, "b"_a, "samples"_a = 1000000, "seed"_a = 1, "threads"_a = py::none(),
        "tmp"_a = py::none(),
        "measure(a, b, samples=1000000, seed=1, threads=None) -> dict\n\n"
        "Hausdorff, mean and RMS distances between two surfaces, each a path or a (vertices, faces) tuple.");
}
