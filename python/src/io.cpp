// SPDX-License-Identifier: MIT
// taxel.io: readers and writers of PLY clouds and meshes, pressure images, contacts and pad
// poses; registration.model_cloud for mesh models.
#include "taxel/io.hpp"
#include "common.hpp"
#include "taxel/registration/model.hpp"
#ifdef TAXEL_PYTHON_HAVE_PNG
#include "taxel/io/png.hpp"
#endif

namespace taxel::python {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

py::array_t<std::uint32_t> triangles_array(const Triangles& t) {
  py::array_t<std::uint32_t> out({static_cast<py::ssize_t>(t.size()), py::ssize_t{3}});
  if (!t.empty()) std::memcpy(out.mutable_data(), t.data(), t.size() * 3 * sizeof(std::uint32_t));
  return out;
}

Triangles triangles_from(const ArrayI64& a, std::size_t vertices) {
  require_shape(a, {-1, 3}, "triangles", "(T, 3)");
  Triangles t(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    const std::int64_t v = a.data()[i];
    if (v < 0 || static_cast<std::uint64_t>(v) >= vertices) {
      throw py::value_error("triangles: vertex index " + std::to_string(v) + " outside [0, " +
                            std::to_string(vertices) + ")");
    }
    t[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)] =
        static_cast<std::uint32_t>(v);
  }
  return t;
}

py::array stack_array(const io::ImageStack& s) {
  ArrayD out({static_cast<py::ssize_t>(s.frames), static_cast<py::ssize_t>(s.rows),
              static_cast<py::ssize_t>(s.cols)});
  std::copy(s.values.begin(), s.values.end(), out.mutable_data());
  return out;
}

}  // namespace

void bind_io(py::module_& root) {
  py::module_ m = root.def_submodule("io", R"doc(
Files: PLY point clouds and meshes, pressure images (.csv, .pgm, .npy, and .png when built
with libpng), contacts CSV and pad poses CSV. Readers raise taxel.IoError (an OSError) naming
the file, the line or byte and the reason; writers replace the target atomically, so a failed
write leaves no partial file.)doc");

  m.def(
      "read_ply",
      [](const std::string& path) {
        io::PlyData d = io::read_ply(path);
        return py::make_tuple(std::move(d.cloud), triangles_array(d.triangles));
      },
      py::arg("path"), "(PointCloud, triangles (T, 3) uint32) of an ASCII or binary PLY file.");
  m.def(
      "write_ply",
      [](const std::string& path, const Cloud& cloud, const std::optional<ArrayI64>& triangles,
         bool binary) {
        const Triangles t = triangles ? triangles_from(*triangles, cloud.size()) : Triangles{};
        io::write_ply(path, cloud,
                      binary ? io::PlyFormat::binary_little_endian : io::PlyFormat::ascii, t);
      },
      py::arg("path"), py::arg("cloud"), py::arg("triangles") = py::none(), py::kw_only(),
      py::arg("binary") = true, "Writes a PointCloud (with its normals and fields) as PLY.");

  m.def(
      "read_image",
      [](const std::string& path) {
#ifdef TAXEL_PYTHON_HAVE_PNG
        if (io::extension(path) == ".png") return stack_array(io::read_png_image(path));
#endif
        return stack_array(io::read_image(path));
      },
      py::arg("path"),
      "A (frames, rows, cols) float64 stack from .csv (one image), .pgm (P2/P5), .npy (2-D or "
      "3-D, any numeric dtype) or a greyscale .png.");
  m.def(
      "write_image",
      [](const std::string& path, const ArrayD& image, double lo, double hi, int maxval) {
        const std::string ext = io::extension(path);
        if (image.ndim() != 2 && image.ndim() != 3) {
          throw py::value_error("write_image: expected (rows, cols) or (frames, rows, cols), got " +
                                shape_text(image));
        }
        const bool stacked = image.ndim() == 3;
        const py::ssize_t rows = image.shape(stacked ? 1 : 0), cols = image.shape(stacked ? 2 : 1);
        std::string bytes;
        if (ext == ".npy") {
          io::ImageStack s{stacked ? image.shape(0) : 1, rows, cols,
                           std::vector<double>(image.data(), image.data() + image.size())};
          bytes = io::encode_npy(s);
        } else if (stacked) {
          throw py::value_error("write_image: a stack of frames can only be written as .npy");
        } else if (ext == ".csv") {
          bytes = io::encode_image_csv(Eigen::Map<const image::ImageD>(image.data(), rows, cols));
        } else if (ext == ".pgm") {
          bytes = io::encode_pgm(Eigen::Map<const image::ImageD>(image.data(), rows, cols), lo, hi,
                                 maxval);
        } else {
          throw py::value_error("write_image: unknown format '" + ext +
                                "' (expected .csv, .pgm or .npy)");
        }
        io::write_file(path, bytes);
      },
      py::arg("path"), py::arg("image"), py::kw_only(), py::arg("lo") = 0.0, py::arg("hi") = 255.0,
      py::arg("maxval") = 255,
      "Writes an image as .csv or .pgm ([lo, hi] mapped to [0, maxval]), or an image or stack "
      "as .npy (float64).");

  m.def(
      "read_contacts_csv",
      [](const std::string& path, bool strict) {
        io::ContactsCsvReport report;
        ContactList cs = io::read_contacts_csv(path, {strict}, &report);
        if (report.skipped_rows > 0) {
          const std::string msg = std::to_string(report.skipped_rows) +
                                  " bad rows skipped, the first: " + report.first_skipped;
          PyErr_WarnEx(PyExc_UserWarning, msg.c_str(), 1);
        }
        return cs;
      },
      py::arg("path"), py::kw_only(), py::arg("strict") = true,
      "Contacts from a CSV with a header (time, x, y, z and optionally the covariance, normal "
      "and pressure columns). strict=False skips bad rows with a UserWarning.");
  m.def(
      "write_contacts_csv",
      [](const std::string& path, const ContactList& contacts) {
        io::write_file(path, io::encode_contacts_csv(contacts));
      },
      py::arg("path"), py::arg("contacts"), "Writes contacts with every column.");

  m.def(
      "read_pad_poses_csv",
      [](const std::string& path) {
        const std::vector<io::PadPose> poses = io::read_pad_poses_csv(path);
        const auto n = static_cast<py::ssize_t>(poses.size());
        py::array_t<std::int64_t> frame(n), pad(n);
        ArrayD time(n), pose({n, py::ssize_t{4}, py::ssize_t{4}});
        for (std::size_t i = 0; i < poses.size(); ++i) {
          frame.mutable_data()[i] = static_cast<std::int64_t>(poses[i].frame);
          pad.mutable_data()[i] = static_cast<std::int64_t>(poses[i].pad);
          time.mutable_data()[i] = poses[i].time;
          for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c)
              pose.mutable_data()[16 * i + 4 * r + c] = poses[i].pose.matrix()(r, c);
          }
        }
        py::dict d;
        d["frame"] = frame;
        d["pad"] = pad;
        d["time"] = time;
        d["pose"] = pose;
        return d;
      },
      py::arg("path"),
      "Pad poses as a dict of 'frame', 'pad', 'time' (NaN where the file has none) and 'pose' "
      "(K, 4, 4) pad -> world.");

  py::module_ reg = root.attr("registration").cast<py::module_>();
  reg.def(
      "model_cloud",
      [](const std::string& path, double spacing, std::uint64_t seed, std::size_t max_points) {
        io::PlyData ply = io::read_ply(path);
        registration::ModelCloud mc;
        {
          py::gil_scoped_release release;
          mc = registration::model_cloud(std::move(ply), {spacing, seed, max_points});
        }
        return py::make_tuple(std::move(mc.cloud), mc.describe());
      },
      py::arg("path"), py::kw_only(), py::arg("spacing") = 1e-3, py::arg("seed") = 1,
      py::arg("max_points") = std::size_t{1} << 22,
      "(PointCloud, description) of a PLY model: a mesh is sampled area-uniformly at about "
      "`spacing` [m] (0: its vertices); a point cloud is taken as it is.");
}

}  // namespace taxel::python
