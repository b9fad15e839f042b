#include "common.hpp"
namespace taxel::python {
void bind_learn(py::module_& m) { m.def_submodule("learn"); }
}
