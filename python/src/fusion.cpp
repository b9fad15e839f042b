// SPDX-License-Identifier: MIT
// taxel.fusion (ContactCloud with the policy and index chosen by name) and taxel.sensor
// (readings of tactile pads to contacts).
#include <functional>
#include <memory>

#include "common.hpp"
#include "index_queries.hpp"
#include "taxel/fusion.hpp"
#include "taxel/index/brute_force.hpp"
#include "taxel/index/dynamic_kdtree.hpp"
#include "taxel/index/voxel_hash.hpp"
#include "taxel/io/pad_poses_csv.hpp"
#include "taxel/sensor/readings.hpp"

namespace taxel::python {
namespace {

using fusion::BatchResult;
using fusion::InsertResult;
using fusion::InsertStatus;

/// Every option of every policy and index, with the C++ defaults.
struct CloudOptions {
  double association_radius = 3.4e-3;
  double association_sigmas = 6.0;
  double process_noise = 0.0;
  std::optional<double> gate_chi2;
  std::optional<double> initial_sigma;
  std::string average_mode = "cumulative";
  double alpha = 0.1;
  double max_normal_angle = 1.2;
  double normal_sigma = 0.05;
  double curvature_prior = 100.0;
  std::size_t leaf_size = 10;
  double max_load_factor = 0.25;
};

/// What Python's ContactCloud calls; one implementation per (policy, index) pair.
class CloudBase {
 public:
  virtual ~CloudBase() = default;
  virtual BatchResult insert(const ContactRows& rows) = 0;
  virtual BatchResult insert(const ContactList& cs) = 0;
  virtual InsertResult insert(const Contact<double>& c) = 0;
  virtual ContactDefect defect(const Contact<double>& c) const = 0;
  virtual std::size_t size() const = 0;
  virtual void clear() = 0;
  virtual void reserve(std::size_t n) = 0;
  virtual std::size_t memory_bytes() const = 0;
  virtual void means(double* out) const = 0;
  virtual void covariances(double* out) const = 0;
  virtual void observations(std::uint32_t* out) const = 0;
  virtual void last_times(double* out) const = 0;
  /// The k points nearest to q and every point within r of q (the index's answers).
  virtual std::vector<index::Neighbor<double>> knn(const Vec3d& q, std::size_t k) const = 0;
  virtual std::vector<index::Neighbor<double>> within(const Vec3d& q, double r) const = 0;
  /// Doubles per point state (the policy's for_each_field).
  virtual std::size_t state_size() const = 0;
  /// Every point's state into out[size() * state_size()].
  virtual void states(double* out) const = 0;
  /// Appends a point from a state written by states() (ContactCloud::restore).
  virtual void restore(const double* state, std::uint32_t observations, double last_time) = 0;
  virtual bool confident(std::size_t id, std::uint32_t min_obs, double max_sigma,
                         double max_normal_sigma) const = 0;
  virtual Cloud to_point_cloud(std::uint32_t min_obs, double max_sigma,
                               double max_normal_sigma) const = 0;
};

template <class F, class I>
class CloudImpl final : public CloudBase {
 public:
  using C = fusion::ContactCloud<F, I>;
  explicit CloudImpl(const typename C::Config& cfg) : cloud_(cfg) {}

  BatchResult insert(const ContactRows& rows) override {
    BatchResult r;
    for (std::size_t i = 0; i < rows.n; ++i) count(r, cloud_.insert(rows.at(i)).status);
    return r;
  }
  BatchResult insert(const ContactList& cs) override { return cloud_.insert(cs); }
  InsertResult insert(const Contact<double>& c) override { return cloud_.insert(c); }
  ContactDefect defect(const Contact<double>& c) const override { return cloud_.defect(c); }
  std::size_t size() const override { return cloud_.size(); }
  void clear() override { cloud_.clear(); }
  void reserve(std::size_t n) override { cloud_.reserve(n); }
  std::size_t memory_bytes() const override { return cloud_.memory_bytes(); }
  void means(double* out) const override {
    for (std::size_t i = 0; i < cloud_.size(); ++i, out += 3) {
      store(out, cloud_.mean(static_cast<index::PointId>(i)));
    }
  }
  void covariances(double* out) const override {
    for (std::size_t i = 0; i < cloud_.size(); ++i, out += 9) {
      store(out, cloud_.covariance(static_cast<index::PointId>(i)));
    }
  }
  void observations(std::uint32_t* out) const override {
    for (std::size_t i = 0; i < cloud_.size(); ++i) {
      out[i] = cloud_.observations(static_cast<index::PointId>(i));
    }
  }
  void last_times(double* out) const override {
    for (std::size_t i = 0; i < cloud_.size(); ++i) {
      out[i] = cloud_.last_time(static_cast<index::PointId>(i));
    }
  }
  std::vector<index::Neighbor<double>> knn(const Vec3d& q, std::size_t k) const override {
    return cloud_.index().knn(q, k);
  }
  std::vector<index::Neighbor<double>> within(const Vec3d& q, double r) const override {
    return cloud_.index().within(q, r);
  }
  std::size_t state_size() const override {
    std::size_t n = 0;
    typename F::State s{};
    F::for_each_field(s, [&](double*, std::size_t k) { n += k; });
    return n;
  }
  void states(double* out) const override {
    for (std::size_t i = 0; i < cloud_.size(); ++i) {
      typename F::State s = cloud_.state(static_cast<index::PointId>(i));
      F::for_each_field(s, [&](const double* v, std::size_t k) {
        std::copy(v, v + k, out);
        out += k;
      });
    }
  }
  void restore(const double* state, std::uint32_t observations, double last_time) override {
    typename F::State s{};
    F::for_each_field(s, [&](double* v, std::size_t k) {
      std::copy(state, state + k, v);
      state += k;
    });
    cloud_.restore(s, observations, last_time);
  }
  bool confident(std::size_t id, std::uint32_t min_obs, double max_sigma,
                 double max_normal_sigma) const override {
    return cloud_.confident(static_cast<index::PointId>(id),
                            {min_obs, max_sigma, max_normal_sigma});
  }
  Cloud to_point_cloud(std::uint32_t min_obs, double max_sigma,
                       double max_normal_sigma) const override {
    return cloud_.to_point_cloud({min_obs, max_sigma, max_normal_sigma});
  }

 private:
  static void count(BatchResult& r, InsertStatus s) {
    r.added += s == InsertStatus::added ? 1 : 0;
    r.fused += s == InsertStatus::fused ? 1 : 0;
    r.rejected += s == InsertStatus::rejected ? 1 : 0;
  }
  C cloud_;
};

constexpr std::pair<std::string_view, int> kPolicies[] = {
    {"surfel", 0}, {"kalman", 1}, {"average", 2}, {"raw", 3}};
constexpr std::pair<std::string_view, int> kIndexes[] = {
    {"voxel_hash", 0}, {"dynamic_kdtree", 1}, {"brute_force", 2}};
constexpr std::pair<std::string_view, fusion::Average<double>::Mode> kAverageModes[] = {
    {"cumulative", fusion::Average<double>::Mode::cumulative},
    {"exponential", fusion::Average<double>::Mode::exponential}};

template <class F>
typename F::Config policy_config(const CloudOptions& o) {
  fusion::Kalman<double>::Config k{o.process_noise, o.gate_chi2, o.initial_sigma};
  if constexpr (std::is_same_v<F, fusion::Kalman<double>>) {
    return k;
  } else if constexpr (std::is_same_v<F, fusion::Surfel<double>>) {
    return {k, o.max_normal_angle, o.normal_sigma, o.curvature_prior};
  } else if constexpr (std::is_same_v<F, fusion::Average<double>>) {
    return {enum_from(o.average_mode, kAverageModes, "average_mode"), o.alpha};
  } else {
    return {};
  }
}

template <class F, class I>
std::unique_ptr<CloudBase> make_cloud(const CloudOptions& o) {
  typename fusion::ContactCloud<F, I>::Config cfg;
  cfg.association_radius = o.association_radius;
  cfg.association_sigmas = o.association_sigmas;
  cfg.fusion = policy_config<F>(o);
  if constexpr (std::is_same_v<I, index::VoxelHash<double>>) {
    cfg.index.max_load_factor = o.max_load_factor;
  } else if constexpr (std::is_same_v<I, index::DynamicKdTree<double>>) {
    cfg.index.leaf_size = o.leaf_size;
  }
  return std::make_unique<CloudImpl<F, I>>(cfg);
}

template <class F>
std::unique_ptr<CloudBase> with_index(int index, const CloudOptions& o) {
  switch (index) {
    case 1:
      return make_cloud<F, index::DynamicKdTree<double>>(o);
    case 2:
      return make_cloud<F, index::BruteForce<double>>(o);
    default:
      return make_cloud<F, index::VoxelHash<double>>(o);
  }
}

/// Refuses an option that the chosen policy or index would ignore.
void check_unused(const CloudOptions& o, int policy, int index) {
  const CloudOptions d;
  const auto refuse = [](const char* options, const char* owner) {
    throw py::value_error(std::string("ContactCloud: set ") + options + " only with " + owner);
  };
  const bool kalman_like = policy == 0 || policy == 1;
  if (!kalman_like) {
    if (o.process_noise != d.process_noise)
      refuse("process_noise", "the surfel and kalman policies");
    if (o.gate_chi2) refuse("gate_chi2", "the surfel and kalman policies");
    if (o.initial_sigma) refuse("initial_sigma", "the surfel and kalman policies");
  }
  if (policy != 0 && (o.max_normal_angle != d.max_normal_angle ||
                      o.normal_sigma != d.normal_sigma || o.curvature_prior != d.curvature_prior)) {
    refuse("max_normal_angle, normal_sigma and curvature_prior", "the surfel policy");
  }
  if (policy != 2 && (o.average_mode != d.average_mode || o.alpha != d.alpha)) {
    refuse("average_mode and alpha", "the average policy");
  }
  if (index != 0 && o.max_load_factor != d.max_load_factor) {
    refuse("max_load_factor", "the voxel_hash index");
  }
  if (index != 1 && o.leaf_size != d.leaf_size) refuse("leaf_size", "the dynamic_kdtree index");
}

/// The Python ContactCloud: a cloud of any (policy, index) pair behind one class.
struct PyContactCloud {
  std::string policy, index;
  double association_radius;
  std::unique_ptr<CloudBase> impl;
  CloudOptions options;  // as constructed: what a pickled cloud is made again from
};

/// A cloud of the named policy and index with options `o` (ValueError for a name or an
/// option that does not apply).
PyContactCloud make_cloud(const std::string& policy, const std::string& index,
                          const CloudOptions& o) {
  const int p = enum_from(policy, kPolicies, "policy");
  const int i = enum_from(index, kIndexes, "index");
  check_unused(o, p, i);
  PyContactCloud c{policy, index, o.association_radius, nullptr, o};
  switch (p) {
    case 1:
      c.impl = with_index<fusion::Kalman<double>>(i, o);
      break;
    case 2:
      c.impl = with_index<fusion::Average<double>>(i, o);
      break;
    case 3:
      c.impl = with_index<fusion::Raw<double>>(i, o);
      break;
    default:
      c.impl = with_index<fusion::Surfel<double>>(i, o);
  }
  return c;
}

py::dict batch_dict(const BatchResult& r) {
  py::dict d;
  d["added"] = r.added;
  d["fused"] = r.fused;
  d["rejected"] = r.rejected;
  return d;
}

/// The first contact of `rows` that `cloud` would reject (an invalid one, or one beyond its
/// index's range), as a ValueError naming the row and the defect.
void check_rows(const CloudBase& cloud, const ContactRows& rows) {
  for (std::size_t i = 0; i < rows.n; ++i) {
    const ContactDefect d = cloud.defect(rows.at(i));
    if (d != ContactDefect::ok) {
      throw py::value_error("contact " + std::to_string(i) + ": " + std::string(to_string(d)) +
                            " (nothing was inserted; strict=False skips invalid contacts)");
    }
  }
}

constexpr std::pair<std::string_view, sensor::ContactMode> kModes[] = {
    {"per_tactel", sensor::ContactMode::per_tactel}, {"per_pad", sensor::ContactMode::per_pad}};

/// Readings and poses as arrays to contacts (see contacts_from_readings' docstring).
ContactList readings_to_contacts(const ArrayU16& readings, const ArrayD& poses,
                                 const std::optional<ArrayD>& times,
                                 const sensor::SensorModel& model,
                                 const sensor::ContactOptions& options, double frame_rate) {
  if (readings.ndim() != 3 && readings.ndim() != 4) {
    throw py::value_error(
        "readings: expected an array of shape (frames, rows, cols) or (frames, pads, rows, "
        "cols), got " +
        shape_text(readings));
  }
  sensor::ReadingStack stack;
  const bool one_pad = readings.ndim() == 3;
  stack.frames = static_cast<std::size_t>(readings.shape(0));
  stack.pads = one_pad ? 1 : static_cast<std::size_t>(readings.shape(1));
  stack.rows = static_cast<std::size_t>(readings.shape(one_pad ? 1 : 2));
  stack.cols = static_cast<std::size_t>(readings.shape(one_pad ? 2 : 3));
  const auto frames = static_cast<py::ssize_t>(stack.frames);
  const auto pads = static_cast<py::ssize_t>(stack.pads);
  if (one_pad) {
    require_shape(poses, {frames, 4, 4}, "poses", "(frames, 4, 4)");
  } else {
    require_shape(poses, {frames, pads, 4, 4}, "poses", "(frames, pads, 4, 4)");
  }
  if (times) require_shape(*times, {frames}, "times", "(frames,)");
  stack.values.assign(readings.data(), readings.data() + readings.size());
  std::vector<io::PadPose> list;
  for (std::size_t f = 0; f < stack.frames; ++f) {
    for (std::size_t p = 0; p < stack.pads; ++p) {
      const double* m = poses.data() + 16 * (f * stack.pads + p);
      if (std::isnan(m[0])) continue;  // no pose: the pad must not read contact
      io::PadPose pose;
      pose.frame = f;
      pose.pad = p;
      if (times) pose.time = times->data()[f];
      if (const char* why = rigid_defect(m, pose.pose)) {
        throw py::value_error("poses[" + std::to_string(f) +
                              (one_pad ? "" : ", " + std::to_string(p)) + "]: " + why);
      }
      list.push_back(pose);
    }
  }
  ContactList out;
  py::gil_scoped_release release;
  sensor::contacts_from_readings(stack, list, model, options, frame_rate, out);
  return out;
}

}  // namespace

void bind_fusion(py::module_& root) {
  // ---- taxel.sensor ---------------------------------------------------------------------------
  py::module_ s =
      root.def_submodule("sensor", "Tactile pads: sensor model and readings to contacts");
  py::class_<sensor::SensorModel>(s, "SensorModel", R"doc(
How a pad of rows x cols tactels at `pitch` [m] turns indentation into readings: a tactel
pressed d [m] reads d / full_scale_depth * (levels - 1) counts plus Gaussian depth noise of
sigma_normal [m]; readings below `threshold` read 0 (censored). sigma_position [m] and
sigma_tilt [rad] are the per-frame noise of the pad pose. Defaults: a Weiss DSA 9205-like pad,
14 x 6 tactels at 3.4 mm, 12-bit. Raises ValueError for a value out of range: the pitch in
[1e-6, 1] m, full_scale_depth in (0, 1] m, the noises in [0, 1] m and sigma_tilt in [0, pi].)doc")
      .def(py::init([](int rows, int cols, double pitch, double full_scale_depth, int levels,
                       int threshold, double sigma_normal, double sigma_position,
                       double sigma_tilt) {
             sensor::SensorModel m;
             m.geometry = {rows, cols, pitch};
             m.full_scale_depth = full_scale_depth;
             m.levels = levels;
             m.threshold = threshold;
             m.sigma_normal = sigma_normal;
             m.sigma_position = sigma_position;
             m.sigma_tilt = sigma_tilt;
             m.validate();
             return m;
           }),
           py::arg("rows") = 14, py::arg("cols") = 6, py::arg("pitch") = 3.4e-3,
           py::arg("full_scale_depth") = 3e-3, py::arg("levels") = 4096, py::arg("threshold") = 8,
           py::arg("sigma_normal") = 0.3e-3, py::arg("sigma_position") = 0.2e-3,
           py::arg("sigma_tilt") = 0.02)
      .def_property_readonly("rows", [](const sensor::SensorModel& m) { return m.geometry.rows; })
      .def_property_readonly("cols", [](const sensor::SensorModel& m) { return m.geometry.cols; })
      .def_property_readonly("pitch", [](const sensor::SensorModel& m) { return m.geometry.pitch; })
      .def_readonly("full_scale_depth", &sensor::SensorModel::full_scale_depth,
                    "indentation that saturates a tactel [m]")
      .def_readonly("levels", &sensor::SensorModel::levels, "reading levels")
      .def_readonly("threshold", &sensor::SensorModel::threshold, "readings below this read 0")
      .def_readonly("sigma_normal", &sensor::SensorModel::sigma_normal,
                    "depth noise of a tactel [m]")
      .def_readonly("sigma_position", &sensor::SensorModel::sigma_position,
                    "per-frame pad translation noise [m]")
      .def_readonly("sigma_tilt", &sensor::SensorModel::sigma_tilt,
                    "per-frame pad tilt noise [rad]")
      .def("depth_per_count", &sensor::SensorModel::depth_per_count, "depth of one count [m]")
      .def(
          "tactel",
          [](const sensor::SensorModel& m, int r, int c) {
            const Vec3d p = m.geometry.tactel(r, c);
            return std::vector<double>{p.x(), p.y(), p.z()};
          },
          py::arg("row"), py::arg("col"), "centre of tactel (row, col) in the pad frame [m]")
      .def("__repr__", [](const sensor::SensorModel& m) {
        return "SensorModel(rows=" + std::to_string(m.geometry.rows) +
               ", cols=" + std::to_string(m.geometry.cols) +
               ", pitch=" + std::to_string(m.geometry.pitch) + ")";
      });

  py::class_<sensor::ContactOptions>(s, "ContactOptions", R"doc(
How readings become contacts: `mode` 'per_tactel' (a contact per active tactel) or 'per_pad'
(one per pad and frame, from a quadric fitted to its depth map; one per tactel in a frame with
fewer than six active, or whose depths the quadric does not fit); `local_normals` (normals from the pad's depth map, else the pad normal, stated as unmeasured); `correct_censoring`
(remove the bias of readings that barely passed the noise floor); `fallback_normal_sigma`
[rad], the slope uncertainty where the depth map cannot measure it; `refine_censoring` (evaluate
that correction at the depth a quadric fitted to the pad predicts, unbiased at the rim of a
contact; False: at the reading itself, about half the cost); `tactel_area` (a reading is the
mean indentation over the tactel's area, as a real tactel's is: each depth is moved to the
centre's where the frame's quadric fits).)doc")
      .def(py::init([](const std::string& mode, bool local_normals, bool correct_censoring,
                       double fallback_normal_sigma, bool refine_censoring, bool tactel_area) {
             sensor::ContactOptions o;
             o.mode = enum_from(mode, kModes, "mode");
             o.local_normals = local_normals;
             o.correct_censoring = correct_censoring;
             o.fallback_normal_sigma = fallback_normal_sigma;
             o.refine_censoring = refine_censoring;
             o.tactel_area = tactel_area;
             o.validate();
             return o;
           }),
           py::arg("mode") = "per_tactel", py::arg("local_normals") = true,
           py::arg("correct_censoring") = true, py::arg("fallback_normal_sigma") = 0.15,
           py::arg("refine_censoring") = true, py::arg("tactel_area") = false)
      .def_property_readonly(
          "mode", [](const sensor::ContactOptions& o) { return enum_name(o.mode, kModes); })
      .def_readonly("local_normals", &sensor::ContactOptions::local_normals,
                    "normals from the pad's depth map (False: the pad normal)")
      .def_readonly("correct_censoring", &sensor::ContactOptions::correct_censoring,
                    "whether near-threshold readings are corrected")
      .def_readonly("refine_censoring", &sensor::ContactOptions::refine_censoring,
                    "whether the correction is taken at the quadric's depth")
      .def_readonly("tactel_area", &sensor::ContactOptions::tactel_area,
                    "whether a reading is the mean over the tactel's area")
      .def_readonly("fallback_normal_sigma", &sensor::ContactOptions::fallback_normal_sigma,
                    "slope uncertainty where the depth map has none [rad]");

  s.def("contacts_from_readings", &readings_to_contacts, py::arg("readings"), py::arg("poses"),
        py::kw_only(), py::arg("times") = py::none(), py::arg("model") = sensor::SensorModel{},
        py::arg("options") = sensor::ContactOptions{}, py::arg("frame_rate") = 1000.0,
        R"doc(
Contacts of pad readings taken at known pad poses.

readings: uint16 counts of shape (frames, rows, cols) for one pad or (frames, pads, rows, cols).
poses: pad -> world 4x4 matrices of shape (frames, 4, 4) or (frames, pads, 4, 4); a pose whose
first entry is NaN means "no pose", allowed only where the pad reads no contact.
times: (frames,) times [s]; default frame / frame_rate.
Raises ValueError for mismatched shapes, readings above the model's levels and non-rigid poses.)doc");
  s.def("truncation_bias", &sensor::truncation_bias, py::arg("measured"), py::arg("threshold"),
        py::arg("sigma"),
        "Mean excess [m] of a reading that survived a threshold under Gaussian noise: "
        "sigma * phi(a) / (1 - Phi(a)), a = (threshold - measured) / sigma.");

  // ---- taxel.fusion ---------------------------------------------------------------------------
  py::module_ f = root.def_submodule("fusion", "Fusion of contacts into a compact cloud");
  f.attr("POLICIES") = py::make_tuple("surfel", "kalman", "average", "raw");
  f.attr("INDEXES") = py::make_tuple("voxel_hash", "dynamic_kdtree", "brute_force");
  py::class_<PyContactCloud>(f, "ContactCloud", R"doc(
A compact cloud of fused contact points (Meier et al. 2011): each contact fuses into the
nearest point within `association_radius` [m], or starts a new point. The gate widens to
`association_sigmas` standard deviations of a contact's noise along its normal when that is
larger, so that a coarse contact's noise tail cannot start a point off the surface (0: off).

policy: 'surfel' (default; a Kalman point that removes the chord sag of curved surfaces),
'kalman' (per-point Kalman filter), 'average' (running mean), 'raw' (every contact kept).
index: 'voxel_hash' (default), 'dynamic_kdtree' or 'brute_force'.
Options that the chosen policy or index does not use must stay at their defaults.)doc")
      .def(py::init([](const std::string& policy, const std::string& index,
                       double association_radius, double association_sigmas, double process_noise,
                       std::optional<double> gate_chi2, std::optional<double> initial_sigma,
                       std::string average_mode, double alpha, double max_normal_angle,
                       double normal_sigma, double curvature_prior, std::size_t leaf_size,
                       double max_load_factor) {
             const CloudOptions o{
                 association_radius, association_sigmas,      process_noise, gate_chi2,
                 initial_sigma,      std::move(average_mode), alpha,         max_normal_angle,
                 normal_sigma,       curvature_prior,         leaf_size,     max_load_factor};
             return make_cloud(policy, index, o);
           }),
           py::arg("policy") = "surfel", py::arg("index") = "voxel_hash", py::kw_only(),
           py::arg("association_radius") = 3.4e-3, py::arg("association_sigmas") = 6.0,
           py::arg("process_noise") = 0.0, py::arg("gate_chi2") = py::none(),
           py::arg("initial_sigma") = py::none(), py::arg("average_mode") = "cumulative",
           py::arg("alpha") = 0.1, py::arg("max_normal_angle") = 1.2,
           py::arg("normal_sigma") = 0.05, py::arg("curvature_prior") = 100.0,
           py::arg("leaf_size") = 10, py::arg("max_load_factor") = 0.25)
      .def(py::pickle(
          [](const PyContactCloud& c) {
            const auto lock = read_lock(&c);
            const CloudOptions& o = c.options;
            const auto n = static_cast<py::ssize_t>(c.impl->size());
            const auto k = static_cast<py::ssize_t>(c.impl->state_size());
            ArrayD states({n, k});
            ArrayD times(n);
            py::array_t<std::uint32_t> obs(n);
            c.impl->states(states.mutable_data());
            c.impl->last_times(times.mutable_data());
            c.impl->observations(obs.mutable_data());
            const py::tuple options = py::make_tuple(
                o.association_radius, o.association_sigmas, o.process_noise, o.gate_chi2,
                o.initial_sigma, o.average_mode, o.alpha, o.max_normal_angle, o.normal_sigma,
                o.curvature_prior, o.leaf_size, o.max_load_factor);
            return py::make_tuple(1, c.policy, c.index, options, states, obs, times);
          },
          [](const py::tuple& t) {
            if (t.size() != 7 || t[0].cast<int>() != 1) {
              throw py::value_error("ContactCloud: not a pickled state of version 1");
            }
            const auto ot = t[3].cast<py::tuple>();
            if (ot.size() != 12) throw py::value_error("ContactCloud: damaged pickled options");
            const CloudOptions o{ot[0].cast<double>(),
                                 ot[1].cast<double>(),
                                 ot[2].cast<double>(),
                                 ot[3].cast<std::optional<double>>(),
                                 ot[4].cast<std::optional<double>>(),
                                 ot[5].cast<std::string>(),
                                 ot[6].cast<double>(),
                                 ot[7].cast<double>(),
                                 ot[8].cast<double>(),
                                 ot[9].cast<double>(),
                                 ot[10].cast<std::size_t>(),
                                 ot[11].cast<double>()};
            PyContactCloud c = make_cloud(t[1].cast<std::string>(), t[2].cast<std::string>(), o);
            const auto states = t[4].cast<ArrayD>();
            const auto obs = t[5].cast<StrictArray<std::uint32_t>>();
            const auto times = t[6].cast<ArrayD>();
            const auto k = static_cast<py::ssize_t>(c.impl->state_size());
            require_shape(states, {-1, k}, "pickled states", "(N, state size)");
            require_shape(obs, {states.shape(0)}, "pickled observations", "(N,)");
            require_shape(times, {states.shape(0)}, "pickled times", "(N,)");
            c.impl->reserve(static_cast<std::size_t>(states.shape(0)));
            try {
              for (py::ssize_t i = 0; i < states.shape(0); ++i) {
                c.impl->restore(states.data() + i * k, obs.data()[i], times.data()[i]);
              }
            } catch (const std::invalid_argument& e) {
              throw py::value_error(std::string("ContactCloud: a pickled point is damaged: ") +
                                    e.what());
            }
            return c;
          }))
      .def(
          "query",
          [](const PyContactCloud& c, const ArrayD& x, std::size_t k) {
            std::size_t n = 0;
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&c);
              n = c.impl->size();
            }
            return knn_query(x, k, n, [&](const Vec3d& q, std::size_t kk) {
              const auto lock = read_lock(&c);
              return c.impl->knn(q, kk);
            });
          },
          py::arg("x"), py::arg("k") = 1,
          (std::string("Nearest fused points (their means; ids are rows of `means`). ") + kQueryDoc)
              .c_str())
      .def(
          "query_ball_point",
          [](const PyContactCloud& c, const ArrayD& x, double r) {
            return radius_query(x, r, [&](const Vec3d& q, double rr) {
              const auto lock = read_lock(&c);
              return c.impl->within(q, rr);
            });
          },
          py::arg("x"), py::arg("r"),
          (std::string("Fused points within r (ids are rows of `means`). ") + kBallDoc).c_str())
      .def_readonly("policy", &PyContactCloud::policy, "the fusion policy's name")
      .def_readonly("index", &PyContactCloud::index, "the spatial index's name")
      .def_readonly("association_radius", &PyContactCloud::association_radius,
                    "the association gate [m]")
      .def("__len__",
           [](const PyContactCloud& c) {
             const auto lock = read_lock(&c);
             return c.impl->size();
           })
      .def(
          "insert",
          [](PyContactCloud& c, ArrayD positions, std::optional<ArrayD> covariances,
             std::optional<ArrayD> normals, std::optional<ArrayD> pressures,
             std::optional<ArrayD> times, std::optional<double> sigma, double footprint_sigma,
             bool strict) {
            const ContactRows rows =
                contact_rows(std::move(positions), std::move(covariances), std::move(normals),
                             std::move(pressures), std::move(times), sigma, footprint_sigma);
            BatchResult r;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&c);
              // Checked under the same lock as the insert: nothing is inserted when one fails.
              // (A py::value_error is a C++ exception until it is raised, with the GIL back.)
              if (strict) check_rows(*c.impl, rows);
              r = c.impl->insert(rows);
            }
            return batch_dict(r);
          },
          py::arg("positions"), py::arg("covariances") = py::none(),
          py::arg("normals") = py::none(), py::arg("pressures") = py::none(),
          py::arg("times") = py::none(), py::kw_only(), py::arg("sigma") = py::none(),
          py::arg("footprint_sigma") = 0.0, py::arg("strict") = true,
          R"doc(
Inserts contacts in row order: positions (N, 3) [m]; covariances (N, 3, 3) or one (3, 3)
[m^2], or an isotropic `sigma` [m] (default 1 mm); normals (N, 3) unit vectors, a NaN row for
none; pressures (N,); times (N,) [s]. `footprint_sigma` [m]: how much of the covariance across
the normal is a footprint around a point on the surface, not scatter (0: all scatter, whose
lift off a curved surface the surfel policy removes). C-contiguous float64 arrays are read in
place.
With strict (default) an invalid contact raises ValueError and nothing is inserted; with
strict=False invalid contacts are skipped and counted. Returns {'added', 'fused', 'rejected'}.)doc")
      .def(
          "insert",
          [](PyContactCloud& c, const ContactList& contacts) {
            BatchResult r;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&c);
              r = c.impl->insert(contacts);
            }
            return batch_dict(r);
          },
          py::arg("contacts"),
          "Inserts a taxel.Contacts in order; invalid contacts are skipped and counted.")
      .def(
          "insert_one",
          [](PyContactCloud& c, const Eigen::Vector3d& position, double sigma, double time) {
            Contact<double> k;
            k.position = position;
            k.covariance = isotropic_covariance(sigma);
            k.time = time;
            InsertResult r;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&c);
              r = c.impl->insert(k);
            }
            if (r.status == InsertStatus::rejected) {
              throw py::value_error("contact: " + std::string(to_string(r.defect)));
            }
            return r.id;
          },
          py::arg("position"), py::arg("sigma") = 1e-3, py::arg("time") = 0.0,
          "Inserts one contact with isotropic noise; returns the id of the point it added to "
          "or started.")
      .def(
          "insert_readings",
          [](PyContactCloud& c, const ArrayU16& readings, const ArrayD& poses,
             const std::optional<ArrayD>& times, const sensor::SensorModel& model,
             const sensor::ContactOptions& options, double frame_rate) {
            const ContactList cs =
                readings_to_contacts(readings, poses, times, model, options, frame_rate);
            BatchResult r;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&c);
              r = c.impl->insert(cs);
            }
            return batch_dict(r);
          },
          py::arg("readings"), py::arg("poses"), py::kw_only(), py::arg("times") = py::none(),
          py::arg("model") = sensor::SensorModel{}, py::arg("options") = sensor::ContactOptions{},
          py::arg("frame_rate") = 1000.0,
          "Turns pad readings into contacts (taxel.sensor.contacts_from_readings) and inserts "
          "them.")
      .def_property_readonly(
          "means",
          [](const PyContactCloud& c) {
            const auto lock = read_lock(&c);
            ArrayD out({static_cast<py::ssize_t>(c.impl->size()), py::ssize_t{3}});
            c.impl->means(out.mutable_data());
            return out;
          },
          "(M, 3) fused point positions [m], in id order")
      .def_property_readonly(
          "covariances",
          [](const PyContactCloud& c) {
            const auto lock = read_lock(&c);
            ArrayD out({static_cast<py::ssize_t>(c.impl->size()), py::ssize_t{3}, py::ssize_t{3}});
            c.impl->covariances(out.mutable_data());
            return out;
          },
          "(M, 3, 3) covariances of the fused points [m^2]")
      .def_property_readonly(
          "observations",
          [](const PyContactCloud& c) {
            const auto lock = read_lock(&c);
            py::array_t<std::uint32_t> out(static_cast<py::ssize_t>(c.impl->size()));
            c.impl->observations(out.mutable_data());
            return out;
          },
          "(M,) contacts fused into each point")
      .def_property_readonly(
          "last_times",
          [](const PyContactCloud& c) {
            const auto lock = read_lock(&c);
            py::array_t<double> out(static_cast<py::ssize_t>(c.impl->size()));
            c.impl->last_times(out.mutable_data());
            return out;
          },
          "(M,) time of the last contact fused into each point [s]")
      .def(
          "confident",
          [](const PyContactCloud& c, std::uint32_t min_observations, double max_sigma,
             double max_normal_sigma) {
            const auto lock = read_lock(&c);
            py::array_t<bool> out(static_cast<py::ssize_t>(c.impl->size()));
            for (std::size_t i = 0; i < c.impl->size(); ++i) {
              out.mutable_data()[i] =
                  c.impl->confident(i, min_observations, max_sigma, max_normal_sigma);
            }
            return out;
          },
          py::kw_only(), py::arg("min_observations") = 1,
          py::arg("max_sigma") = std::numeric_limits<double>::infinity(),
          py::arg("max_normal_sigma") = std::numeric_limits<double>::infinity(),
          "(M,) bool: points with at least min_observations contacts whose largest standard "
          "deviation is at most max_sigma [m] and smallest (across the surface) at most "
          "max_normal_sigma [m]")
      .def(
          "to_point_cloud",
          [](const PyContactCloud& c, std::uint32_t min_observations, double max_sigma,
             double max_normal_sigma) {
            const auto lock = read_lock(&c);
            return c.impl->to_point_cloud(min_observations, max_sigma, max_normal_sigma);
          },
          py::kw_only(), py::arg("min_observations") = 1,
          py::arg("max_sigma") = std::numeric_limits<double>::infinity(),
          py::arg("max_normal_sigma") = std::numeric_limits<double>::infinity(),
          "The confident points as a PointCloud with fields 'observations', 'cov_xx' .. "
          "'cov_zz', 'last_time' (and normals with the surfel policy).")
      .def(
          "clear",
          [](PyContactCloud& c) {
            const auto lock = write_lock(&c);
            c.impl->clear();
          },
          "Removes every point; the options stay.")
      .def(
          "reserve",
          [](PyContactCloud& c, std::size_t n) {
            const auto lock = write_lock(&c);
            try {
              c.impl->reserve(n);
            } catch (const std::length_error&) {
              throw py::value_error("reserve: n = " + std::to_string(n) +
                                    " points is more than a cloud can hold");
            }
          },
          py::arg("n"), "Makes room for n points (MemoryError when memory runs out).")
      .def_property_readonly("memory_bytes",
                             [](const PyContactCloud& c) {
                               const auto lock = read_lock(&c);
                               return c.impl->memory_bytes();
                             })
      .def("__repr__", [](const PyContactCloud& c) {
        const auto lock = read_lock(&c);
        return "ContactCloud(policy='" + c.policy + "', index='" + c.index + "', " +
               std::to_string(c.impl->size()) + " points)";
      });
}

}  // namespace taxel::python
