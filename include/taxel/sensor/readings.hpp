// SPDX-License-Identifier: MIT
// Readings in, contacts out: a stack of pad readings with the pads' poses per frame, turned
// into contacts by one ContactExtractor (contacts.hpp). The input a user with a real sensor has:
// the frames the controller delivered (e.g. a .npy stack, io/npy.hpp) and the poses the
// robot's forward kinematics gave (io/pad_poses_csv.hpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/io/npy.hpp"
#include "taxel/io/pad_poses_csv.hpp"
#include "taxel/sensor/contacts.hpp"
#include "taxel/sensor/pad.hpp"

namespace taxel::sensor {

/// Frames of readings: `frames` x `pads` pads of `rows` x `cols` tactels, row-major, frame
/// outermost (the layout of a numpy array of shape (frames, pads, rows, cols)).
struct ReadingStack {
  std::size_t frames = 0;             ///< frames in the stack
  std::size_t pads = 0;               ///< pads per frame
  std::size_t rows = 0;               ///< tactel rows per pad
  std::size_t cols = 0;               ///< tactel columns per pad
  std::vector<std::uint16_t> values;  ///< frames * pads * rows * cols readings

  /// The stack of a .npy array of shape (frames, rows, cols) (one pad) or (frames, pads,
  /// rows, cols). Throws std::invalid_argument for another number of dimensions, or a pad of
  /// more than 4096 rows or columns (SensorModel's limit; an empty stack may claim any size).
  static ReadingStack from_npy(io::NpyU16 array) {
    ReadingStack s;
    const auto& d = array.shape;
    if (d.size() == 3) {
      s = {d[0], 1, d[1], d[2], {}};
    } else if (d.size() == 4) {
      s = {d[0], d[1], d[2], d[3], {}};
    } else {
      throw std::invalid_argument(
          "readings: expected an array of shape (frames, rows, cols) or (frames, pads, rows, "
          "cols), got " +
          std::to_string(d.size()) + " dimensions");
    }
    if (s.rows > 4096 || s.cols > 4096) {
      throw std::invalid_argument("readings: pads of " + std::to_string(s.rows) + " x " +
                                  std::to_string(s.cols) +
                                  " tactels; a sensor model has at most 4096 rows and columns");
    }
    s.values = std::move(array.values);
    return s;
  }
  /// The readings of pad `pad` in frame `frame`, as a rows x cols matrix.
  template <class = void>
  PadMatrix pad(std::size_t frame, std::size_t pad) const {
    PadMatrix m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    const std::size_t n = rows * cols;
    const std::uint16_t* at = values.data() + (frame * pads + pad) * n;
    std::copy(at, at + n, m.data());
    return m;
  }
};

/// Counts of `contacts_from_readings`.
struct ReadingsSummary {
  std::size_t pad_frames = 0;  ///< (frame, pad) readings with a pose
  std::size_t touching = 0;    ///< of which some tactel read above the threshold
  std::size_t contacts = 0;    ///< contacts made
};

/// Contacts of every (frame, pad) that has a pose in `poses`, in the order of `poses`, by the
/// measurement model of contacts.hpp. The contact time is the pose's time, or frame /
/// `frame_rate` when the pose has none. Throws std::invalid_argument when the model's rows and
/// columns differ from the stack's, when a pose names a frame or pad outside the stack, or
/// when a pad with readings above the threshold has no pose (its contacts could not be
/// placed); the message names the frame and pad.
template <class = void>
inline ReadingsSummary contacts_from_readings(const ReadingStack& stack,
                                              std::span<const io::PadPose> poses,
                                              const SensorModel& model,
                                              const ContactOptions& options, double frame_rate,
                                              std::vector<Contact<double>>& out) {
  model.validate();
  if (std::size_t(model.geometry.rows) != stack.rows ||
      std::size_t(model.geometry.cols) != stack.cols) {
    throw std::invalid_argument("readings: the pads have " + std::to_string(stack.rows) + " x " +
                                std::to_string(stack.cols) + " tactels, the sensor model " +
                                std::to_string(model.geometry.rows) + " x " +
                                std::to_string(model.geometry.cols));
  }
  if (!(frame_rate > 0) || !std::isfinite(frame_rate)) {
    throw std::invalid_argument("readings: frame_rate must be finite and > 0");
  }
  if (stack.values.size() != stack.frames * stack.pads * stack.rows * stack.cols) {
    throw std::invalid_argument("readings: the stack's size disagrees with its shape");
  }
  for (std::size_t i = 0; i < stack.values.size(); ++i) {
    if (stack.values[i] >= model.levels) {
      const std::size_t per_frame = stack.pads * stack.rows * stack.cols;
      throw std::invalid_argument(
          "readings: frame " + std::to_string(i / per_frame) + " reads " +
          std::to_string(stack.values[i]) + ", above the sensor's largest level " +
          std::to_string(model.levels - 1) + " (set the levels of the sensor model)");
    }
  }
  std::vector<bool> posed(stack.frames * stack.pads, false);
  for (const io::PadPose& p : poses) {
    if (p.frame >= stack.frames || p.pad >= stack.pads) {
      throw std::invalid_argument("readings: a pose for frame " + std::to_string(p.frame) +
                                  ", pad " + std::to_string(p.pad) + ", but the stack has " +
                                  std::to_string(stack.frames) + " frames of " +
                                  std::to_string(stack.pads) + " pads");
    }
    posed[p.frame * stack.pads + p.pad] = true;
  }
  const std::size_t n = stack.rows * stack.cols;
  for (std::size_t i = 0; i < posed.size(); ++i) {
    if (posed[i]) continue;
    const std::uint16_t* at = stack.values.data() + i * n;
    for (std::size_t k = 0; k < n; ++k) {
      if (at[k] >= model.threshold) {
        throw std::invalid_argument("readings: frame " + std::to_string(i / stack.pads) + ", pad " +
                                    std::to_string(i % stack.pads) +
                                    " reads contact but has no pose");
      }
    }
  }
  ContactExtractor extractor(model, options);
  ReadingsSummary summary;
  for (const io::PadPose& p : poses) {
    const PadMatrix counts = stack.pad(p.frame, p.pad);
    const double time = std::isfinite(p.time) ? p.time : double(p.frame) / frame_rate;
    const std::size_t made = extractor.extract(counts, p.pose, time, out);
    ++summary.pad_frames;
    summary.touching += made > 0 ? 1 : 0;
    summary.contacts += made;
  }
  return summary;
}

}  // namespace taxel::sensor
