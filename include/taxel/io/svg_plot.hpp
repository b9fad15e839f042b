// SPDX-License-Identifier: MIT
// Line plots as standalone SVG text: a few series of (x, y) points with markers, axes with
// 1-2-5 ticks, labels and a legend. Enough for study results (accuracy against noise, error
// against contacts) that open in any browser; not a plotting library. And pictures of point
// clouds: an orthographic view, points coloured by a value, with a colour bar.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/io/picture.hpp"

namespace taxel::io {

/// One line of a plot. Points with a non-finite coordinate are left out (the line breaks).
struct PlotSeries {
  std::string name;       ///< Legend text.
  std::vector<double> x;  ///< Abscissae.
  std::vector<double> y;  ///< Ordinates, one per abscissa.
};

/// A line plot. Axis limits default to the data's range, widened to whole ticks.
struct LinePlot {
  std::string title;               ///< Title above the picture.
  std::string x_label;             ///< Label of the x axis, with its unit.
  std::string y_label;             ///< Label of the y axis, with its unit.
  std::vector<PlotSeries> series;  ///< The lines.
  bool reverse_x = false;          ///< x decreases to the right (e.g. falling SNR)
  double y_min = std::numeric_limits<double>::quiet_NaN();  ///< NaN: from the data
  double y_max = std::numeric_limits<double>::quiet_NaN();  ///< NaN: from the data
  int width = 640;                                          ///< [px]
  int height = 400;                                         ///< [px]
};

namespace detail {

inline std::string svg_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out.push_back(c);
    }
  }
  return out;
}

inline std::string svg_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

inline std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 6), v == 0.0 ? 0.0 : v);
  return buf;
}

// A 1-2-5 step giving about `target` intervals over [lo, hi].
inline double nice_step(double lo, double hi, int target) {
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10.0 * mag;
}

}  // namespace detail

/// Renders `plot` as a complete SVG document. Throws std::invalid_argument when a series'
/// x and y differ in length or the size is below 160 x 120.
inline std::string render_svg(const LinePlot& plot) {
  using detail::svg_escape;
  using detail::svg_num;
  if (plot.width < 160 || plot.height < 120) {
    throw std::invalid_argument("render_svg: the plot must be at least 160 x 120 pixels");
  }
  double x_lo = std::numeric_limits<double>::infinity();
  double x_hi = -x_lo;
  double y_lo = x_lo;
  double y_hi = -x_lo;
  for (const PlotSeries& s : plot.series) {
    if (s.x.size() != s.y.size()) {
      throw std::invalid_argument("render_svg: series '" + s.name + "' has " +
                                  std::to_string(s.x.size()) + " x values and " +
                                  std::to_string(s.y.size()) + " y values");
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  }
  if (!(x_lo <= x_hi)) {  // no finite point
    x_lo = 0.0;
    x_hi = 1.0;
    y_lo = 0.0;
    y_hi = 1.0;
  }
  if (std::isfinite(plot.y_min)) y_lo = plot.y_min;
  if (std::isfinite(plot.y_max)) y_hi = plot.y_max;
  if (x_hi - x_lo <= 0.0) {
    x_lo -= 0.5;
    x_hi += 0.5;
  }
  if (y_hi - y_lo <= 0.0) {
    y_lo -= 0.5;
    y_hi += 0.5;
  }
  const double x_step = detail::nice_step(x_lo, x_hi, 6);
  const double y_step = detail::nice_step(y_lo, y_hi, 6);
  x_lo = std::floor(x_lo / x_step + 1e-9) * x_step;
  x_hi = std::ceil(x_hi / x_step - 1e-9) * x_step;
  if (!std::isfinite(plot.y_min)) y_lo = std::floor(y_lo / y_step + 1e-9) * y_step;
  if (!std::isfinite(plot.y_max)) y_hi = std::ceil(y_hi / y_step - 1e-9) * y_step;

  const double left = 64.0;
  const double right = plot.width - 16.0;
  const double top = plot.title.empty() ? 16.0 : 36.0;
  const double bottom = plot.height - 48.0;
  const auto px = [&](double x) {
    const double t = (x - x_lo) / (x_hi - x_lo);
    return left + (plot.reverse_x ? 1.0 - t : t) * (right - left);
  };
  const auto py = [&](double y) { return bottom - (y - y_lo) / (y_hi - y_lo) * (bottom - top); };

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                    std::to_string(plot.width) + "\" height=\"" + std::to_string(plot.height) +
                    "\" viewBox=\"0 0 " + std::to_string(plot.width) + " " +
                    std::to_string(plot.height) +
                    "\" font-family=\"sans-serif\" font-size=\"12\">\n"
                    "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  if (!plot.title.empty()) {
    svg += "<text x=\"" + svg_num(0.5 * (left + right)) +
           "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" + svg_escape(plot.title) +
           "</text>\n";
  }
  // Grid and ticks.
  for (double v = x_lo; v <= x_hi + 0.5 * x_step; v += x_step) {
    const std::string x = svg_num(px(v));
    svg += "<line x1=\"" + x + "\" y1=\"" + svg_num(top) + "\" x2=\"" + x + "\" y2=\"" +
           svg_num(bottom) + "\" stroke=\"#e0e0e0\"/>\n<text x=\"" + x + "\" y=\"" +
           svg_num(bottom + 16) + "\" text-anchor=\"middle\">" + detail::tick_label(v, x_step) +
           "</text>\n";
  }
  for (double v = y_lo; v <= y_hi + 0.5 * y_step; v += y_step) {
    const std::string y = svg_num(py(v));
    svg += "<line x1=\"" + svg_num(left) + "\" y1=\"" + y + "\" x2=\"" + svg_num(right) +
           "\" y2=\"" + y + "\" stroke=\"#e0e0e0\"/>\n<text x=\"" + svg_num(left - 6) + "\" y=\"" +
           svg_num(py(v) + 4) + "\" text-anchor=\"end\">" + detail::tick_label(v, y_step) +
           "</text>\n";
  }
  svg += "<rect x=\"" + svg_num(left) + "\" y=\"" + svg_num(top) + "\" width=\"" +
         svg_num(right - left) + "\" height=\"" + svg_num(bottom - top) +
         "\" fill=\"none\" stroke=\"#333\"/>\n";
  svg += "<text x=\"" + svg_num(0.5 * (left + right)) + "\" y=\"" + svg_num(plot.height - 12.0) +
         "\" text-anchor=\"middle\">" + svg_escape(plot.x_label) + "</text>\n";
  svg += "<text transform=\"translate(16 " + svg_num(0.5 * (top + bottom)) +
         ") rotate(-90)\" text-anchor=\"middle\">" + svg_escape(plot.y_label) + "</text>\n";

  static constexpr std::array<const char*, 8> kColours{"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                                       "#9467bd", "#8c564b", "#e377c2", "#17becf"};
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const char* colour = kColours[k % kColours.size()];
    std::string path;
    bool pen_down = false;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        pen_down = false;
        continue;
      }
      path += (pen_down ? " L" : " M") + svg_num(px(s.x[i])) + " " + svg_num(py(s.y[i]));
      pen_down = true;
      svg += "<circle cx=\"" + svg_num(px(s.x[i])) + "\" cy=\"" + svg_num(py(s.y[i])) +
             "\" r=\"3\" fill=\"" + colour + "\"/>\n";
    }
    if (!path.empty()) {
      svg += "<path d=\"" + path.substr(1) + "\" fill=\"none\" stroke=\"" + colour +
             "\" stroke-width=\"2\"/>\n";
    }
    const double ly = top + 16.0 + 18.0 * static_cast<double>(k);
    svg += "<line x1=\"" + svg_num(right - 170) + "\" y1=\"" + svg_num(ly - 4) + "\" x2=\"" +
           svg_num(right - 146) + "\" y2=\"" + svg_num(ly - 4) + "\" stroke=\"" + colour +
           "\" stroke-width=\"2\"/>\n<text x=\"" + svg_num(right - 140) + "\" y=\"" + svg_num(ly) +
           "\">" + svg_escape(s.name) + "</text>\n";
  }
  svg += "</svg>\n";
  return svg;
}

/// A view of a point cloud for render_cloud_svg.
struct CloudView {
  std::string title;            ///< Title above the picture.
  std::string value_label;      ///< what the colour shows, with its unit
  double azimuth_deg = 35.0;    ///< rotation about the world z axis
  double elevation_deg = 25.0;  ///< tilt of the view above the x-y plane
  double point_radius = 2.2;    ///< [px]
  int width = 420;              ///< [px]
  int height = 360;             ///< [px]
  double value_min = std::numeric_limits<double>::quiet_NaN();  ///< NaN: from the data
  double value_max = std::numeric_limits<double>::quiet_NaN();  ///< NaN: from the data
};

/// An SVG picture of `points` seen orthographically from (azimuth, elevation), far points drawn
/// first, each coloured by `values[i]` (ramp of picture.hpp) with a colour bar; `values` may be
/// empty (one colour). Non-finite points are left out. Throws std::invalid_argument when the
/// sizes differ or the picture is smaller than 160 x 120.
template <class = void>
inline std::string render_cloud_svg(const std::vector<Vec3d>& points,
                                    const std::vector<double>& values, const CloudView& view) {
  using detail::svg_escape;
  using detail::svg_num;
  if (!values.empty() && values.size() != points.size()) {
    throw std::invalid_argument("render_cloud_svg: " + std::to_string(values.size()) +
                                " values for " + std::to_string(points.size()) + " points");
  }
  if (view.width < 160 || view.height < 120) {
    throw std::invalid_argument("render_cloud_svg: the picture must be at least 160 x 120");
  }
  const double az = view.azimuth_deg * 3.14159265358979323846 / 180.0;
  const double el = view.elevation_deg * 3.14159265358979323846 / 180.0;
  // Screen axes: right, up, and towards the viewer.
  const Vec3d right(std::cos(az), std::sin(az), 0.0);
  const Vec3d toward(-std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  const Vec3d up = toward.cross(right);
  struct P {
    double x, y, depth, value;
  };
  std::vector<P> ps;
  double vlo = std::numeric_limits<double>::infinity(), vhi = -vlo;
  double xlo = vlo, xhi = -vlo, ylo = vlo, yhi = -vlo;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const double v = values.empty() ? 0.0 : values[i];
    ps.push_back({points[i].dot(right), points[i].dot(up), points[i].dot(toward), v});
    xlo = std::min(xlo, ps.back().x);
    xhi = std::max(xhi, ps.back().x);
    ylo = std::min(ylo, ps.back().y);
    yhi = std::max(yhi, ps.back().y);
    if (std::isfinite(v)) {
      vlo = std::min(vlo, v);
      vhi = std::max(vhi, v);
    }
  }
  if (std::isfinite(view.value_min)) vlo = view.value_min;
  if (std::isfinite(view.value_max)) vhi = view.value_max;
  std::sort(ps.begin(), ps.end(), [](const P& a, const P& b) { return a.depth < b.depth; });
  const double top = 30.0, bottom = 20.0, left = 15.0, bar = 70.0;
  const double w = view.width - left - bar, h = view.height - top - bottom;
  const double span = std::max({xhi - xlo, yhi - ylo, 1e-12});
  const double scale = ps.empty() ? 1.0 : std::min(w, h) / span;
  const double cx = left + 0.5 * w - scale * 0.5 * (xlo + xhi);
  const double cy = top + 0.5 * h + scale * 0.5 * (ylo + yhi);
  const auto colour = [&](double v) {
    const auto rgb = ramp(vhi > vlo ? (v - vlo) / (vhi - vlo) : 0.5);
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
    return std::string(buf);
  };
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                    std::to_string(view.width) + "\" height=\"" + std::to_string(view.height) +
                    "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += "<text x=\"" + svg_num(0.5 * view.width) + "\" y=\"18\" text-anchor=\"middle\">" +
         svg_escape(view.title) + "</text>\n";
  for (const P& p : ps) {
    svg += "<circle cx=\"" + svg_num(cx + scale * p.x) + "\" cy=\"" + svg_num(cy - scale * p.y) +
           "\" r=\"" + svg_num(view.point_radius) + "\" fill=\"" + colour(p.value) + "\"/>\n";
  }
  if (!values.empty() && std::isfinite(vlo)) {
    const double bx = view.width - bar + 15.0;
    for (int k = 0; k < 20; ++k) {
      const double y = top + h * (1.0 - (k + 1) / 20.0);
      svg += "<rect x=\"" + svg_num(bx) + "\" y=\"" + svg_num(y) + "\" width=\"12\" height=\"" +
             svg_num(h / 20.0 + 0.5) + "\" fill=\"" + colour(vlo + (vhi - vlo) * (k + 0.5) / 20.0) +
             "\"/>\n";
    }
    char lo[32], hi[32];
    std::snprintf(lo, sizeof lo, "%.3g", vlo);
    std::snprintf(hi, sizeof hi, "%.3g", vhi);
    svg +=
        "<text x=\"" + svg_num(bx + 16) + "\" y=\"" + svg_num(top + 10) + "\">" + hi + "</text>\n";
    svg +=
        "<text x=\"" + svg_num(bx + 16) + "\" y=\"" + svg_num(top + h) + "\">" + lo + "</text>\n";
    svg += "<text x=\"" + svg_num(bx + 6) + "\" y=\"" + svg_num(top + h + 15) +
           "\" text-anchor=\"middle\">" + svg_escape(view.value_label) + "</text>\n";
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace taxel::io
