// The Python module's translation layer: Python values to and from the pipeline's plain data
// (JSON objects, points, meshes as numpy arrays), the library's errors as Python exceptions, and
// pipeline calls made with the GIL released and Ctrl-C turned into cancellation.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "errors.h"
#include "geometry.h"
#include "util/progress.h"

namespace lacuna {
namespace python {

namespace py = pybind11;

// The exception classes of the module (lacuna.LacunaError and its subclasses), created by
// register_errors().
struct ErrorClasses {
  PyObject* base = nullptr;            // LacunaError
  PyObject* invalid_input = nullptr;   // InvalidInputError, also a ValueError
  PyObject* file = nullptr;            // FileError, also an OSError (and a ValueError)
  PyObject* resource_limit = nullptr;  // ResourceLimitError
  PyObject* check_failed = nullptr;    // CheckFailedError
  PyObject* internal = nullptr;        // InternalError, also a RuntimeError
  PyObject* cancelled = nullptr;       // CancelledError
};
const ErrorClasses& errors();

// Adds the exception classes to the module and translates the library's errors into them.
void register_errors(py::module_& m);

// Raises `type` with `message` and, when given, the attribute `report`.
[[noreturn]] void raise(PyObject* type, const std::string& message, const py::object& report = py::none());

// A Python value as JSON: dicts with string keys, lists, tuples, strings, numbers, booleans, None,
// numpy arrays and scalars, os.PathLike (as its path). `other` converts anything else (a solid as
// its name) or returns false. Throws py::type_error naming `where` for what cannot be converted.
using OtherValue = std::function<bool(const py::handle& value, nlohmann::json& out)>;
nlohmann::json to_json(const py::handle& value, const std::string& where, const OtherValue& other = {});

// JSON as Python values (dicts, lists, str, int, float, bool, None).
py::object from_json(const nlohmann::json& value);

// An N x 3 array of points (any real dtype) as points; throws ValueError naming `what` otherwise.
std::vector<Vec3d> to_points(const py::handle& array, const std::string& what);

// A point or direction of three numbers; throws ValueError naming `what` otherwise.
Vec3d to_vec3(const py::handle& value, const std::string& what);

// Points as a new N x 3 float64 array; 2D points as N x 2.
py::array_t<double> points_array(const std::vector<Vec3d>& points);
py::array_t<double> points_array(const std::vector<Vec2d>& points);

// Numbers as a new 1D float64 array.
py::array_t<double> numbers_array(const std::vector<double>& values);

// Index rows as an M x k uint32 array when they all have k entries, else a list of 1D arrays.
py::object index_rows(const std::vector<std::vector<uint32_t>>& rows);

// A path given as str or os.PathLike.
std::string path_of(const py::handle& value);

// A progress sink that cancels the call when Python has a signal to handle (Ctrl-C): at stage starts
// and steps (at most every 20 ms) the calling thread briefly takes the GIL and runs the signal
// handlers; an exception they raise (KeyboardInterrupt) stops the call and is raised again once it
// has unwound.
class SignalSink : public ProgressSink {
 public:
  SignalSink();
  ~SignalSink() override;
  void begin(const std::string&, uint64_t) override {}
  void advance(uint64_t) override {}
  void end() override {}
  bool cancelled() const override;
  // Raises the exception a signal handler raised (GIL held); false when there was none.
  bool restore();

 private:
  std::thread::id owner_;
  mutable std::chrono::steady_clock::time_point last_look_{};
  mutable std::atomic<bool> stop_{false};
  mutable PyObject* type_ = nullptr;
  mutable PyObject* value_ = nullptr;
  mutable PyObject* trace_ = nullptr;
};

// Calls `f` (which must not touch Python objects) with the GIL released, reporting to a
// SignalSink: Ctrl-C raises KeyboardInterrupt once the library has stopped and cleaned up.
template <class F>
auto released(F&& f) -> decltype(f()) {
  SignalSink sink;
  try {
    py::gil_scoped_release release;
    ProgressSinkScope scope(&sink);
    return f();
  } catch (const Cancelled&) {
    if (sink.restore()) throw py::error_already_set();
    throw;
  }
}

// Gigabytes (10^9 bytes) as bytes; None or 0 gives 0 (the library's default budget).
uint64_t budget_bytes(const py::object& max_memory_gb);

}  // namespace python
}  // namespace lacuna
