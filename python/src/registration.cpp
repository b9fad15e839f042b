#include "common.hpp"
namespace taxel::python {
void bind_registration(py::module_& m) { m.def_submodule("registration"); }
}
