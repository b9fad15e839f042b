// SPDX-License-Identifier: MIT
// Fuzzes the libsvm data reader and the LIBLINEAR model reader with arbitrary bytes (the first
// byte picks one). A reader must throw taxel::IoError or return a consistent, finite result; a
// data set that reads is trained on (LinearSvm) and predicted, and a model that reads predicts.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/io/libsvm_format.hpp>
#include <taxel/learn/linear_svm.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int which = data[0] % 3;
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (which == 2) bytes = "solver_type L2R_L2LOSS_SVC_DUAL\nnr_class " + bytes;
  try {
    if (which < 2) {
      const taxel::learn::Dataset d =
          taxel::io::parse_libsvm(bytes, "<fuzz>", {.dims = 0, .max_values = 1 << 16});
      if (d.rows() < 1 || d.dims() < 1 || d.y.size() != static_cast<std::size_t>(d.rows()) ||
          !d.x.allFinite() || (!d.groups.empty() && d.groups.size() != d.y.size())) {
        std::abort();
      }
      taxel::learn::LinearSvm m(taxel::learn::LinearSvmConfig{.max_iterations = 20});
      const taxel::Outcome o = m.fit(d.view());
      if (o.ok() || o.status == taxel::Status::not_converged) {
        if (!m.weights().allFinite()) std::abort();
        (void)m.predict(d.x.row(0).transpose());
        (void)taxel::io::parse_libsvm(taxel::io::encode_libsvm(d.view()));
      }
    } else {
      const taxel::learn::LinearSvm m = taxel::learn::LinearSvm::load(bytes);
      if (m.dims() > 0 && m.dims() < 100000) {
        (void)m.predict(Eigen::VectorXd::Zero(m.dims()));
      }
    }
  } catch (const taxel::IoError&) {
  }
  return 0;
}
