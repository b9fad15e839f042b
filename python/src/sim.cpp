#include "common.hpp"
namespace taxel::python {
void bind_sim(py::module_& m) { m.def_submodule("sim"); }
}
