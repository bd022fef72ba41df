// The `clearway` Python module: numpy in and out, the GIL released during every check, and bad input
// raised as a Python exception carrying the library's message (file, element, reason).
#include "bindings.h"

#include <clearway/load/load_error.h>

namespace py = pybind11;

PYBIND11_MODULE(clearway, m) {
  m.doc() = "Clearway: exact collision checking for motion planning (scenes, certified motions, GJK/EPA, audits).";

  // LoadError keeps the parts of the C++ exception as attributes, so that callers can point at the file.
  py::object load_error = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("clearway.LoadError",
                                "A robot, mesh, scene or map file that cannot be loaded: str(e) is "
                                "'FILE: ELEMENT: REASON'; e.file, e.element and e.reason hold the parts.",
                                PyExc_RuntimeError, nullptr));
  m.attr("LoadError") = load_error;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const clearway::LoadError& e) {
      const py::object type = py::module_::import("clearway").attr("LoadError");
      py::object error = type(e.what());
      error.attr("file") = e.file();
      error.attr("element") = e.element();
      error.attr("reason") = e.reason();
      PyErr_SetObject(type.ptr(), error.ptr());
    }
  });

  clearway::python::bindNarrowphase(m);
  clearway::python::bindScene(m);
  clearway::python::bindRobot(m);
#ifdef CLEARWAY_PYTHON_HAVE_OMPL
  clearway::python::bindPlanning(m);
#endif
}
