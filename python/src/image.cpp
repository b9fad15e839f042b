#include "common.hpp"
namespace taxel::python {
void bind_image(py::module_& m) { m.def_submodule("image"); }
}
