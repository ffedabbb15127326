#include "python/convert.h"

#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <cstring>

namespace lacuna {
namespace python {
namespace {

ErrorClasses g_errors;

PyObject* new_error(py::module_& m, const char* name, const char* doc, std::vector<PyObject*> bases) {
  py::tuple tuple(bases.size());
  for (size_t i = 0; i < bases.size(); ++i) tuple[i] = py::reinterpret_borrow<py::object>(bases[i]);
  const std::string qualified = std::string("lacuna.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, tuple.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::reinterpret_borrow<py::object>(type));
  return type;
}

}  // namespace

const ErrorClasses& errors() { return g_errors; }

void register_errors(py::module_& m) {
  ErrorClasses& e = g_errors;
  e.base = new_error(m, "LacunaError", "Every error Lacuna raises on purpose; the message says what to change.",
                     {PyExc_Exception});
  e.invalid_input = new_error(m, "InvalidInputError",
                              "Bad arguments, recipes or input meshes: the message names the key or file, and what "
                              "was expected (the message the command line prints). A ValueError.",
                              {e.base, PyExc_ValueError});
  e.file = new_error(m, "FileError", "A file that cannot be opened, read or written. An OSError and a ValueError.",
                     {e.base, PyExc_OSError, PyExc_ValueError});
  e.resource_limit = new_error(m, "ResourceLimitError",
                               "The job would exceed the memory budget (or a size limit); refused before allocating. "
                               "The message names a voxel size that would fit.",
                               {e.base});
  e.check_failed = new_error(m, "CheckFailedError",
                             "A result failed its validity checks; nothing was written. `report` holds the report "
                             "when there is one.",
                             {e.base});
  e.internal = new_error(m, "InternalError", "A broken invariant inside Lacuna: a bug. A RuntimeError.",
                         {e.base, PyExc_RuntimeError});
  e.cancelled = new_error(m, "CancelledError", "The call was cancelled; nothing was left behind.", {e.base});
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidInput& x) {
      PyErr_SetString(g_errors.invalid_input, x.what());
    } catch (const IoError& x) {
      PyErr_SetString(g_errors.file, x.what());
    } catch (const ResourceLimit& x) {
      PyErr_SetString(g_errors.resource_limit, x.what());
    } catch (const CheckFailed& x) {
      PyErr_SetString(g_errors.check_failed, x.what());
    } catch (const InternalError& x) {
      PyErr_SetString(g_errors.internal, x.what());
    } catch (const Cancelled& x) {
      PyErr_SetString(g_errors.cancelled, x.what());
    }
  });
}

void raise(PyObject* type, const std::string& message, const py::object& report) {
  py::object error = py::reinterpret_borrow<py::object>(type)(message);
  if (!report.is_none()) error.attr("report") = report;
  PyErr_SetObject(type, error.ptr());
  throw py::error_already_set();
}

nlohmann::json to_json(const py::handle& value, const std::string& where, const OtherValue& other) {
  if (other) {
    nlohmann::json out;
    if (other(value, out)) return out;
  }
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::int_>(value)) {
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
    if (overflow > 0) return value.cast<unsigned long long>();
    if (overflow < 0) throw py::value_error(where + ": integer out of range");
    return v;
  }
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json out = nlohmann::json::object();
    for (auto item : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(item.first)) throw py::type_error(where + ": dictionary keys must be strings");
      const std::string key = item.first.cast<std::string>();
      out[key] = to_json(item.second, where + "." + key, other);
    }
    return out;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    nlohmann::json out = nlohmann::json::array();
    size_t i = 0;
    for (auto item : value) out.push_back(to_json(item, where + "[" + std::to_string(i++) + "]", other));
    return out;
  }
  if (py::isinstance<py::array>(value)) {
    py::array a = py::reinterpret_borrow<py::array>(value);
    const char kind = a.dtype().kind();
    if (kind == 'f' || kind == 'i' || kind == 'u') {
      // Numbers straight from the buffer: a large array costs no Python objects.
      const bool integral = kind != 'f';
      py::array flat = integral ? py::array(py::array_t<int64_t, py::array::c_style | py::array::forcecast>(a))
                                : py::array(py::array_t<double, py::array::c_style | py::array::forcecast>(a));
      std::vector<ssize_t> shape(a.shape(), a.shape() + a.ndim());
      size_t at = 0;
      std::function<nlohmann::json(size_t)> build = [&](size_t axis) -> nlohmann::json {
        if (axis == shape.size()) {
          const size_t i = at++;
          if (integral) return static_cast<const int64_t*>(flat.data())[i];
          return static_cast<const double*>(flat.data())[i];
        }
        nlohmann::json out = nlohmann::json::array();
        for (ssize_t k = 0; k < shape[axis]; ++k) out.push_back(build(axis + 1));
        return out;
      };
      return build(0);
    }
    return to_json(a.attr("tolist")(), where, other);
  }
  py::module_ numbers = py::module_::import("numbers");
  if (py::isinstance(value, numbers.attr("Integral")))
    return to_json(py::int_(py::reinterpret_borrow<py::object>(value)), where, other);
  if (py::isinstance(value, numbers.attr("Real")))
    return py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
  if (py::hasattr(value, "__fspath__")) return path_of(value);
  throw py::type_error(where + ": cannot use a value of type " +
                       std::string(py::str(value.get_type().attr("__name__"))));
}

py::object from_json(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.get<uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(value.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& item : value) out.append(from_json(item));
      return std::move(out);
    }
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (auto it = value.begin(); it != value.end(); ++it) out[py::str(it.key())] = from_json(it.value());
      return std::move(out);
    }
    default:
      return py::none();
  }
}

std::vector<Vec3d> to_points(const py::handle& value, const std::string& what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(what + ": expected an N x 3 array of points (mm)");
  std::vector<Vec3d> points(size_t(a.shape(0)));
  static_assert(sizeof(Vec3d) == 3 * sizeof(double), "Vec3d is three packed doubles");
  if (!points.empty()) std::memcpy(static_cast<void*>(points.data()), a.data(), points.size() * sizeof(Vec3d));
  return points;
}

Vec3d to_vec3(const py::handle& value, const std::string& what) {
  std::vector<double> v;
  try {
    v = value.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
  }
  if (v.size() != 3) throw py::value_error(what + ": expected three numbers [x, y, z]");
  return Vec3d{v[0], v[1], v[2]};
}

py::array_t<double> points_array(const std::vector<Vec3d>& points) {
  py::array_t<double> a({py::ssize_t(points.size()), py::ssize_t(3)});
  if (!points.empty()) std::memcpy(a.mutable_data(), points.data(), points.size() * sizeof(Vec3d));
  return a;
}

py::array_t<double> points_array(const std::vector<Vec2d>& points) {
  py::array_t<double> a({py::ssize_t(points.size()), py::ssize_t(2)});
  double* out = a.mutable_data();
  for (size_t i = 0; i < points.size(); ++i) {
    out[2 * i] = points[i].x;
    out[2 * i + 1] = points[i].y;
  }
  return a;
}

py::array_t<double> numbers_array(const std::vector<double>& values) {
  py::array_t<double> a(py::ssize_t(values.size()));
  if (!values.empty()) std::memcpy(a.mutable_data(), values.data(), values.size() * sizeof(double));
  return a;
}

py::object index_rows(const std::vector<std::vector<uint32_t>>& rows) {
  const size_t k = rows.empty() ? 0 : rows.front().size();
  bool uniform = !rows.empty();
  for (const auto& r : rows) uniform = uniform && r.size() == k;
  if (uniform) {
    py::array_t<uint32_t> a({py::ssize_t(rows.size()), py::ssize_t(k)});
    uint32_t* out = a.mutable_data();
    for (const auto& r : rows) out = std::copy(r.begin(), r.end(), out);
    return std::move(a);
  }
  py::list out;
  for (const auto& r : rows) {
    py::array_t<uint32_t> a(py::ssize_t(r.size()));
    std::copy(r.begin(), r.end(), a.mutable_data());
    out.append(a);
  }
  return std::move(out);
}

std::string path_of(const py::handle& value) {
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::hasattr(value, "__fspath__")) {
    py::object p = value.attr("__fspath__")();
    if (py::isinstance<py::str>(p)) return p.cast<std::string>();
  }
  throw py::type_error("expected a path (str or os.PathLike), got " +
                       std::string(py::str(value.get_type().attr("__name__"))));
}

SignalSink::SignalSink() : owner_(std::this_thread::get_id()) {}

SignalSink::~SignalSink() {
  if (!type_ && !value_ && !trace_) return;
  py::gil_scoped_acquire gil;
  Py_XDECREF(type_);
  Py_XDECREF(value_);
  Py_XDECREF(trace_);
}

bool SignalSink::cancelled() const {
  if (stop_.load()) return true;
  // Signal handlers run on the main thread only, and only the thread that made the call holds it.
  if (std::this_thread::get_id() != owner_) return false;
  // Steps come thousands of times a second; a look every 20 ms answers Ctrl-C at once all the same.
  const auto now = std::chrono::steady_clock::now();
  if (now - last_look_ < std::chrono::milliseconds(20)) return false;
  last_look_ = now;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() == 0) return false;
  PyErr_Fetch(&type_, &value_, &trace_);
  stop_ = true;
  return true;
}

bool SignalSink::restore() {
  if (!type_) return false;
  PyErr_Restore(type_, value_, trace_);
  type_ = value_ = trace_ = nullptr;
  return true;
}

uint64_t budget_bytes(const py::object& max_memory_gb) {
  if (max_memory_gb.is_none()) return 0;
  const double gb = max_memory_gb.cast<double>();
  if (!(gb > 0) || !std::isfinite(gb)) throw py::value_error("max_memory_gb: expected a positive number of gigabytes");
  return uint64_t(gb * 1e9);
}

}  // namespace python
}  // namespace lacuna
