// The extension module glint._glint: glint.Error, the process-wide settings, and the edges, io,
// denoise submodules and the Reconstruction class (one source file each). The Python package
// glint (python/glint/) re-exports them.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>

#include "bindings.h"
#include "core/build_info.h"
#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace py = pybind11;

namespace {

// The --threads limit; replaced by each set_threads().
std::unique_ptr<tbb::global_control> thread_limit;

}  // namespace

PYBIND11_MODULE(_glint, m) {
  m.doc() = "glint's C++ core (use the package glint, which re-exports it).";

  static py::exception<glint::Error> error_type(m, "Error", PyExc_RuntimeError);
  error_type.doc() =
      "Raised for bad inputs and failed work, with the one-line message the glint CLI prints\n"
      "(file: element: reason). Attributes: file, element, reason (element may be '').";
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const glint::Error& e) {
      py::object error = py::reinterpret_borrow<py::object>(error_type)(e.what());
      error.attr("file") = e.file();
      error.attr("element") = e.element();
      error.attr("reason") = e.reason();
      PyErr_SetObject(error_type.ptr(), error.ptr());
    }
  });

  m.attr("__version__") = glint::build_info().version;
  m.attr("cuda") = glint::build_info().cuda;

  // A library prints no progress bars and only warnings unless asked (the CLI's defaults are
  // for a terminal).
  glint::set_quiet(true);
  glint::set_log_level("warn");
  m.def(
      "set_threads",
      [](int threads) {
        if (threads < 0) throw glint::Error("threads", "", "must be 0 or more");
        thread_limit.reset();
        thread_limit = glint::limit_threads(threads);
      },
      py::arg("threads"),
      "Limit glint's worker threads (the CLI's --threads); 0 = all cores (the default).");
  m.def(
      "set_quiet", [](bool quiet) { glint::set_quiet(quiet); }, py::arg("quiet"),
      "Progress bars on stderr off (True, the module's default) or on (False; shown only when\n"
      "stderr is a terminal), as the CLI's --quiet.");
  m.def(
      "set_log_level", [](const std::string& level) { glint::set_log_level(level); },
      py::arg("level"),
      "Log level of glint's messages on stderr: trace, debug, info, warn (the module's\n"
      "default), error or off, as the CLI's --log-level.");

  glint::python::bind_edges(m.def_submodule("edges", "BoundED point-cloud edge detection."));
  glint::python::bind_io(m.def_submodule("io", "Point clouds, images and RGB-D sequences."));
  glint::python::bind_denoise(m.def_submodule("denoise", "Locally-guided image denoising."));
  glint::python::bind_reconstruction(m);
}
