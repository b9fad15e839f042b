#include "common.hpp"
namespace taxel::python {
void bind_io(py::module_& m) { m.def_submodule("io"); }
}
