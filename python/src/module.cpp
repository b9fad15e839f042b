// SPDX-License-Identifier: MIT
// The extension module taxel._taxel; the package `taxel` re-exports it.
#include "common.hpp"
#include "taxel/core/error.hpp"
#include "taxel/version.hpp"

PYBIND11_MODULE(_taxel, m) {
  namespace tp = taxel::python;
  m.doc() = "taxel: tactile perception (the compiled part of the taxel package)";
  m.attr("__version__") = TAXEL_VERSION_STRING;
  // File and format errors are OSErrors whose message names the file, the line and the reason.
  pybind11::register_exception<taxel::IoError>(m, "IoError", PyExc_OSError).doc() =
      "A file or data format error (an OSError): the message names the file, the line "
      "or byte, and the reason.";
  pybind11::register_exception<taxel::ProtocolError>(m, "ProtocolError", PyExc_OSError).doc() =
      "A device answered outside its protocol (an OSError naming the device and the "
      "reply).";
  tp::bind_core(m);
  tp::bind_fusion(m);
  tp::bind_index(m);
  tp::bind_registration(m);
  tp::bind_image(m);
  tp::bind_learn(m);
  tp::bind_io(m);
  tp::bind_sim(m);
  tp::bind_optical(m);
  tp::bind_shape(m);
}
