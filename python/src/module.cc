// _gyrodrift: the compiled half of the Python package `gyrodrift` (python/gyrodrift/__init__.py
// re-exports it with docstrings and examples; docs/python.md).
//
// The bindings only convert: numpy arrays to Eigen and back, keyword arguments to the library's
// option structs (named as the CLI flags name them, `-` as `_`), results to dicts. Every number
// comes from the same library calls the CLI makes, so the same inputs and options give the same
// bits (python/tests/test_cli_parity.py). Long calls run without the GIL, report progress to an
// optional callable and stop at Ctrl-C (LongCall, bindings.h). Library errors become
// gyrodrift.UsageError (ValueError), DataError (ValueError) and FileError (OSError) with the
// library's one-line message.
//
// This file creates the module and its exception types; each operation's bindings live in their
// own file (bindings.h lists them).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/version.h"

namespace py = pybind11;

PYBIND11_MODULE(_gyrodrift, m) {
  namespace gp = gyrodrift::python;
  using py::arg;
  m.doc() = "Compiled core of the gyrodrift package; import gyrodrift instead.";
  m.attr("__version__") = gyrodrift::kVersion;

  // Python exception types, created here so the translator can raise them; __init__ re-exports.
  static py::exception<gyrodrift::UsageError> usage_error(m, "UsageError", PyExc_ValueError);
  static py::exception<gyrodrift::DataError> data_error(m, "DataError", PyExc_ValueError);
  static py::exception<gyrodrift::IoError> file_error(m, "FileError", PyExc_OSError);
  static py::exception<gyrodrift::Error> other_error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const gyrodrift::UsageError& e) {  // OptionError included
      usage_error(e.what());
    } catch (const gyrodrift::DataError& e) {
      data_error(e.what());
    } catch (const gyrodrift::IoError& e) {
      file_error(e.what());
    } catch (const gyrodrift::Error& e) {
      other_error(e.what());
    }
  });

  gp::BindSignal(m);
  gp::BindDriftModel(m);
  gp::BindExport(m);
  gp::BindEvaluate(m);
  gp::BindFleet(m);
  gp::BindLogs(m);
  gp::BindDemo(m);
}
