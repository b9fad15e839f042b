// SPDX-License-Identifier: MIT
// Heights from surface gradients by Poisson integration: the 5-point Laplacian of the height
// equals the divergence of the gradients (Simchony, Chellappa and Shao, "Direct analytical
// methods for solving Poisson equations in computer vision problems", IEEE TPAMI 12(5), 1990).
// Two borders:
//  - free (the default): the heights whose forward differences best match the gradients
//    averaged to the half-pixel points between pixel centres, in least squares, with no
//    gradient across the frame's border (Neumann). Solved by the type-II discrete cosine
//    transform (DCT-II) in both directions; the free constant is set so that the pixels the
//    caller marks as untouched average zero. Contacts may reach the border.
//  - zero: the height is 0 on the border, the divergence taken by central differences.
//    Solved by the type-I discrete sine transform (DST-I).
// The DCT-II takes one N-point FFT per two rows (Makhoul's reordering, below); the DST-I the
// FFT of the odd extension of length 2 (N + 1), X_k = -Im(Y_k) / 2, two rows per FFT. The
// Laplacian's eigenvalues on those bases are 2 cos(pi k / M) + 2 cos(pi l / N) - 4 (cosines) and 2
// cos(pi k / (m + 1)) + 2 cos(pi l / (n + 1)) - 4 (sines). The FFT is Eigen's
// (unsupported/Eigen/FFT, kissfft inside): header-only and already a dependency, so the optical
// layer adds none.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "taxel/optical/types.hpp"

namespace taxel::optical {

/// What the integration assumes at the frame's border (see the header comment).
enum class PoissonBorder { free, zero };

/// Integrates gradient planes of one size into heights; keeps its FFT plans, so reusing it for
/// frames of that size allocates nothing. Not thread-safe: one per thread.
class PoissonSolver {
 public:
  /// A solver for rows x cols planes (at least 3 x 3). Throws std::invalid_argument otherwise.
  PoissonSolver(int rows, int cols) : rows_(rows), cols_(cols) {
    image::detail::checked_pixels("PoissonSolver", rows, cols);
    if (rows < 3 || cols < 3) {
      throw std::invalid_argument("PoissonSolver: planes of at least 3 x 3 pixels, got " +
                                  std::to_string(rows) + " x " + std::to_string(cols));
    }
    m_ = rows - 2;
    n_ = cols - 2;
    work_.resize(m_, n_);
  }

  /// A solver for rows x cols planes, no larger than this one's: this one for its own size,
  /// else one kept for reuse (the 16 most recently made). reconstruct integrates a contact's
  /// neighbourhood through it.
  PoissonSolver& part(int rows, int cols) {
    if (rows > rows_ || cols > cols_) {
      throw std::invalid_argument("PoissonSolver::part: larger than the solver's planes");
    }
    if (rows == rows_ && cols == cols_) return *this;
    for (auto& p : parts_) {
      if (p->rows() == rows && p->cols() == cols) return *p;
    }
    if (parts_.size() >= 16) parts_.erase(parts_.begin());
    parts_.push_back(std::make_unique<PoissonSolver>(rows, cols));
    return *parts_.back();
  }

  /// Rows of the planes this solver takes.
  int rows() const noexcept { return rows_; }
  /// Columns of the planes this solver takes.
  int cols() const noexcept { return cols_; }

  /// The height [m] whose gradient best matches (gx, gy) (dimensionless: height over distance,
  /// x along columns, y along rows), for pixels `pixel` [m] apart. With the free border, the
  /// pixels where `untouched` is non-zero average zero height (all pixels when it is empty).
  /// Throws std::invalid_argument for planes of another size or a pixel size not finite and
  /// > 0.
  template <class = void>
  Plane integrate(const Plane& gx, const Plane& gy, double pixel,
                  PoissonBorder border = PoissonBorder::free, const image::Mask& untouched = {}) {
    check(gx, "gx");
    check(gy, "gy");
    if (!(pixel > 0) || !std::isfinite(pixel)) {
      throw std::invalid_argument("PoissonSolver: the pixel size must be finite and > 0 [m]");
    }
    if (untouched.size() != 0 && (untouched.rows() != rows_ || untouched.cols() != cols_)) {
      throw std::invalid_argument("PoissonSolver: the untouched mask differs in size");
    }
    if (border == PoissonBorder::free) return integrate_free(gx, gy, pixel, untouched);
    // The divergence by central differences, times pixel^2 (the Laplacian's scale), on the
    // interior.
    const double half = 0.5 * pixel;
    for (int i = 0; i < m_; ++i) {
      for (int j = 0; j < n_; ++j) {
        const int r = i + 1, c = j + 1;
        work_(i, j) = half * ((gx(r, c + 1) - gx(r, c - 1)) + (gy(r + 1, c) - gy(r - 1, c)));
      }
    }
    dst_rows(work_);
    dst_cols(work_);
    const double pi = std::numbers::pi;
    for (int i = 0; i < m_; ++i) {
      const double ci = 2.0 * std::cos(pi * (i + 1) / (m_ + 1)) - 4.0;
      for (int j = 0; j < n_; ++j) {
        work_(i, j) /= ci + 2.0 * std::cos(pi * (j + 1) / (n_ + 1));
      }
    }
    dst_rows(work_);
    dst_cols(work_);
    work_ *= 4.0 / (double(m_ + 1) * double(n_ + 1));
    Plane h = Plane::Zero(rows_, cols_);
    h.block(1, 1, m_, n_) = work_;
    return h;
  }

  /// The DCT-II of each row of `a` in place (see the header comment); exposed for its test.
  template <class = void>
  void dct_rows(Plane& a) {
    cosine(a, false, false);
  }
  /// The DCT-II of each column of `a` in place.
  template <class = void>
  void dct_cols(Plane& a) {
    cosine(a, true, false);
  }
  /// The inverse of dct_rows (a scaled DCT-III).
  template <class = void>
  void idct_rows(Plane& a) {
    cosine(a, false, true);
  }
  /// The inverse of dct_cols.
  template <class = void>
  void idct_cols(Plane& a) {
    cosine(a, true, true);
  }

  /// The DST-I of each row of `a` in place (see the header comment); exposed for its test.
  template <class = void>
  void dst_rows(Plane& a) {
    transform(a, false);
  }
  /// The DST-I of each column of `a` in place.
  template <class = void>
  void dst_cols(Plane& a) {
    transform(a, true);
  }

 private:
  void check(const Plane& p, const char* name) const {
    if (p.rows() != rows_ || p.cols() != cols_) {
      throw std::invalid_argument(std::string("PoissonSolver: ") + name + " is " +
                                  std::to_string(p.rows()) + " x " + std::to_string(p.cols()) +
                                  ", the solver's planes are " + std::to_string(rows_) + " x " +
                                  std::to_string(cols_));
    }
  }

  template <class = void>
  Plane integrate_free(const Plane& gx, const Plane& gy, double pixel,
                       const image::Mask& untouched) {
    // Gradients at the half-pixel points (zero across the border), times the pixel size: the
    // height differences to match. Their divergence is the right-hand side.
    Plane f(rows_, cols_);
    for (int r = 0; r < rows_; ++r) {
      for (int c = 0; c < cols_; ++c) {
        const double east = c + 1 < cols_ ? 0.5 * (gx(r, c) + gx(r, c + 1)) : 0.0;
        const double west = c > 0 ? 0.5 * (gx(r, c - 1) + gx(r, c)) : 0.0;
        const double south = r + 1 < rows_ ? 0.5 * (gy(r, c) + gy(r + 1, c)) : 0.0;
        const double north = r > 0 ? 0.5 * (gy(r - 1, c) + gy(r, c)) : 0.0;
        f(r, c) = pixel * ((east - west) + (south - north));
      }
    }
    dct_rows(f);
    dct_cols(f);
    // The Laplacian's eigenvalues, 2 cos(pi r / rows) + 2 cos(pi c / cols) - 4, from cosines
    // computed once per solver.
    if (cos_rows_.empty()) {
      const double pi = std::numbers::pi;
      for (int r = 0; r < rows_; ++r) cos_rows_.push_back(2.0 * std::cos(pi * r / rows_) - 4.0);
      for (int c = 0; c < cols_; ++c) cos_cols_.push_back(2.0 * std::cos(pi * c / cols_));
    }
    for (int r = 0; r < rows_; ++r) {
      const double cr = cos_rows_[static_cast<std::size_t>(r)];
      for (int c = r == 0 ? 1 : 0; c < cols_; ++c) {
        f(r, c) /= cr + cos_cols_[static_cast<std::size_t>(c)];
      }
    }
    f(0, 0) = 0.0;  // the mean, free
    idct_rows(f);
    idct_cols(f);
    double sum = 0, n = 0;
    for (int r = 0; r < rows_; ++r) {
      for (int c = 0; c < cols_; ++c) {
        if (untouched.size() != 0 && !untouched(r, c)) continue;
        sum += f(r, c);
        n += 1;
      }
    }
    if (n > 0) f -= sum / n;
    return f;
  }

  // DCT-II (forward) or its inverse along rows or columns by Makhoul's reordering (Makhoul, "A
  // fast cosine transform in one and multiple dimensions", IEEE TASSP 28(1), 1980): with
  // v_n = x_2n and v_(N-1-n) = x_(2n+1), X_k = Re(e^(-i pi k / 2N) V_k), V the N-point FFT of v;
  // the inverse takes V_k = e^(i pi k / 2N) (X_k - i X_(N-k)) (X_N = 0) back through the
  // inverse FFT. Two real sequences share one complex FFT: forward, their spectra are
  // (Z_k + conj Z_(N-k)) / 2 and (Z_k - conj Z_(N-k)) / 2i; inverse, V_a + i V_b transforms to
  // v_a + i v_b.
  template <class = void>
  void cosine(Plane& a, bool columns, bool inverse) {
    const Eigen::Index count = columns ? a.cols() : a.rows();
    const Eigen::Index len = columns ? a.rows() : a.cols();
    const auto n = static_cast<std::size_t>(len);
    const auto at = [&](Eigen::Index seq, Eigen::Index k) -> double& {
      return columns ? a(k, seq) : a(seq, k);
    };
    const double pi = std::numbers::pi;
    // The twiddles of this length, computed once per direction (rows and columns differ).
    std::vector<std::complex<double>>& twiddle = twiddles_[columns ? 1 : 0];
    if (twiddle.size() != n) {
      twiddle.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        twiddle[k] = std::polar(1.0, -pi * double(k) / double(2 * len));
      }
    }
    // Where x_j goes in v: even j to j / 2, odd j to N - 1 - (j - 1) / 2.
    const auto slot = [n](std::size_t j) { return j % 2 == 0 ? j / 2 : n - 1 - (j - 1) / 2; };
    in_.resize(n);
    for (Eigen::Index s = 0; s < count; s += 2) {
      const bool pair = s + 1 < count;
      if (!inverse) {
        for (std::size_t j = 0; j < n; ++j) {
          const auto jj = static_cast<Eigen::Index>(j);
          in_[slot(j)] = std::complex<double>(at(s, jj), pair ? at(s + 1, jj) : 0.0);
        }
        fft_.fwd(out_, in_);
        for (std::size_t k = 0; k < n; ++k) {
          const std::complex<double> z = out_[k], zc = std::conj(out_[k == 0 ? 0 : n - k]);
          const std::complex<double> va = 0.5 * (z + zc),
                                     vb = std::complex<double>(0, -0.5) * (z - zc);
          const auto kk = static_cast<Eigen::Index>(k);
          at(s, kk) = (twiddle[k] * va).real();
          if (pair) at(s + 1, kk) = (twiddle[k] * vb).real();
        }
      } else {
        for (std::size_t k = 0; k < n; ++k) {
          const auto kk = static_cast<Eigen::Index>(k);
          const auto back = static_cast<Eigen::Index>(n - k);
          const std::complex<double> rot = std::conj(twiddle[k]);
          const std::complex<double> va =
              rot * std::complex<double>(at(s, kk), k == 0 ? 0.0 : -at(s, back));
          const std::complex<double> vb =
              pair ? rot * std::complex<double>(at(s + 1, kk), k == 0 ? 0.0 : -at(s + 1, back))
                   : std::complex<double>(0.0, 0.0);
          in_[k] = va + std::complex<double>(0, 1) * vb;
        }
        fft_.inv(out_, in_);
        for (std::size_t j = 0; j < n; ++j) {
          const auto jj = static_cast<Eigen::Index>(j);
          at(s, jj) = out_[slot(j)].real();
          if (pair) at(s + 1, jj) = out_[slot(j)].imag();
        }
      }
    }
  }

  // Two sequences per complex FFT of length 2 (len + 1).
  template <class = void>
  void transform(Plane& a, bool columns) {
    const Eigen::Index count = columns ? a.cols() : a.rows();
    const Eigen::Index len = columns ? a.rows() : a.cols();
    const auto size = static_cast<std::size_t>(2 * (len + 1));
    in_.assign(size, std::complex<double>(0.0, 0.0));
    const auto at = [&](Eigen::Index seq, Eigen::Index k) -> double& {
      return columns ? a(k, seq) : a(seq, k);
    };
    for (Eigen::Index s = 0; s < count; s += 2) {
      const bool pair = s + 1 < count;
      for (Eigen::Index k = 0; k < len; ++k) {
        const std::complex<double> v(at(s, k), pair ? at(s + 1, k) : 0.0);
        in_[static_cast<std::size_t>(k + 1)] = v;
        in_[size - 1 - static_cast<std::size_t>(k)] = -v;
      }
      fft_.fwd(out_, in_);
      for (Eigen::Index k = 0; k < len; ++k) {
        const std::complex<double> z = out_[static_cast<std::size_t>(k + 1)];
        at(s, k) = -0.5 * z.imag();
        if (pair) at(s + 1, k) = 0.5 * z.real();
      }
    }
  }

  int rows_, cols_, m_, n_;
  Plane work_;
  std::vector<double> cos_rows_, cos_cols_;            // integrate_free's eigenvalue terms
  std::vector<std::unique_ptr<PoissonSolver>> parts_;  // part()'s solvers, oldest first
  Eigen::FFT<double> fft_;
  std::vector<std::complex<double>> in_, out_;
  std::vector<std::complex<double>> twiddles_[2];  // cosine()'s, along rows and along columns
};

}  // namespace taxel::optical
