// SPDX-License-Identifier: MIT
// A UVC camera through Video4Linux2 (Linux), for camera-based tactile sensors: GelSight Mini
// and DIGIT are UVC devices (/dev/video*). Memory-mapped streaming; frames come out as 8-bit
// RGB (optical::RgbFrame) from YUYV 4:2:2 (converted here, ITU-R BT.601 limited range) or,
// when the drivers are built with libjpeg (TAXEL_DRIVERS_HAVE_JPEG, which CMake's
// taxel::drivers sets when it finds libjpeg), from Motion-JPEG. The Linux kernel's V4L2 API
// (linux/videodev2.h) is the only dependency.
#pragma once

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/io/picture.hpp"

#if defined(TAXEL_DRIVERS_HAVE_JPEG)
#include "taxel/io/jpeg.hpp"
#endif

namespace taxel::drivers {

/// YUYV 4:2:2 (Y0 U Y1 V per two pixels) to 8-bit RGB by ITU-R BT.601 with limited range
/// (Y in [16, 235], U and V in [16, 240]), the UVC default: R = 1.164 (Y - 16) + 1.596 (V - 128),
/// G = 1.164 (Y - 16) - 0.392 (U - 128) - 0.813 (V - 128), B = 1.164 (Y - 16) + 2.017 (U - 128),
/// rounded and clamped to [0, 255]. `in` holds width * height * 2 bytes, width even.
inline void yuyv_to_rgb(const std::uint8_t* in, int width, int height, io::RgbImage& out) {
  out.rows = height;
  out.cols = width;
  out.data.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  const auto clamp = [](double v) {
    return static_cast<std::uint8_t>(std::clamp(v + 0.5, 0.0, 255.0));
  };
  std::uint8_t* o = out.data.data();
  const std::size_t pairs = static_cast<std::size_t>(width / 2) * static_cast<std::size_t>(height);
  for (std::size_t i = 0; i < pairs; ++i, in += 4) {
    const double u = double(in[1]) - 128.0, v = double(in[3]) - 128.0;
    for (const std::uint8_t y : {in[0], in[2]}) {
      const double c = 1.164 * (double(y) - 16.0);
      *o++ = clamp(c + 1.596 * v);
      *o++ = clamp(c - 0.392 * u - 0.813 * v);
      *o++ = clamp(c + 2.017 * u);
    }
  }
}

/// What to ask a camera for.
struct UvcOptions {
  int width = 0;    ///< frame width [px]; 0 keeps the camera's current one
  int height = 0;   ///< frame height [px]; 0 keeps the camera's current one
  int buffers = 4;  ///< memory-mapped buffers, in [2, 32]
};

/// A V4L2 capture device streaming frames. Move-only; stops streaming and closes on destruction.
class UvcCamera {
 public:
  /// Opens `device` (/dev/video0), sets YUYV (or, with libjpeg, Motion-JPEG when the camera
  /// has no YUYV) at the size asked, maps the buffers and starts streaming. Throws IoError
  /// naming the device: it cannot be opened (no camera there: `ls /dev/video*`), is not a V4L2
  /// capture device, offers neither format, or refuses a request.
  explicit UvcCamera(std::string device = "/dev/video0", const UvcOptions& options = {})
      : device_(std::move(device)) {
    if (options.buffers < 2 || options.buffers > 32 || options.width < 0 || options.height < 0) {
      throw IoError(device_, "buffers must be in [2, 32] and the size >= 0");
    }
    fd_ = ::open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
      fail(std::string("cannot open: ") + std::strerror(errno) +
           " (no camera there? ls /dev/video*)");
    }
    v4l2_capability cap{};
    if (xioctl(VIDIOC_QUERYCAP, &cap) != 0) {
      fail(std::string("is not a Video4Linux2 device (VIDIOC_QUERYCAP: ") + std::strerror(errno) +
           ")");
    }
    const std::uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
      fail("is not a video capture device with streaming I/O");
    }
    card_ = reinterpret_cast<const char*>(cap.card);
    // The formats offered: YUYV first, Motion-JPEG when it can be decoded.
    bool yuyv = false, mjpeg = false;
    for (std::uint32_t i = 0;; ++i) {
      v4l2_fmtdesc d{};
      d.index = i;
      d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(VIDIOC_ENUM_FMT, &d) != 0) break;
      yuyv = yuyv || d.pixelformat == V4L2_PIX_FMT_YUYV;
      mjpeg = mjpeg || d.pixelformat == V4L2_PIX_FMT_MJPEG;
    }
#if !defined(TAXEL_DRIVERS_HAVE_JPEG)
    if (!yuyv && mjpeg) fail("offers Motion-JPEG only: build the drivers with libjpeg");
#endif
    if (!yuyv && !mjpeg) fail("offers neither YUYV nor Motion-JPEG frames");
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(VIDIOC_G_FMT, &fmt) != 0) fail_errno("VIDIOC_G_FMT");
    fmt.fmt.pix.pixelformat = yuyv ? V4L2_PIX_FMT_YUYV : V4L2_PIX_FMT_MJPEG;
    if (options.width > 0) fmt.fmt.pix.width = static_cast<std::uint32_t>(options.width);
    if (options.height > 0) fmt.fmt.pix.height = static_cast<std::uint32_t>(options.height);
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(VIDIOC_S_FMT, &fmt) != 0) fail_errno("VIDIOC_S_FMT");
    format_ = fmt.fmt.pix.pixelformat;
    width_ = static_cast<int>(fmt.fmt.pix.width);
    height_ = static_cast<int>(fmt.fmt.pix.height);
    if ((options.width > 0 && width_ != options.width) ||
        (options.height > 0 && height_ != options.height)) {
      fail("gives " + std::to_string(width_) + " x " + std::to_string(height_) + ", not the " +
           std::to_string(options.width) + " x " + std::to_string(options.height) + " asked");
    }
    v4l2_requestbuffers req{};
    req.count = static_cast<std::uint32_t>(options.buffers);
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(VIDIOC_REQBUFS, &req) != 0 || req.count < 2) fail_errno("VIDIOC_REQBUFS");
    for (std::uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (xioctl(VIDIOC_QUERYBUF, &b) != 0) fail_errno("VIDIOC_QUERYBUF");
      void* p = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
      if (p == MAP_FAILED) fail_errno("mmap");
      maps_.push_back({p, b.length});
      if (xioctl(VIDIOC_QBUF, &b) != 0) fail_errno("VIDIOC_QBUF");
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(VIDIOC_STREAMON, &type) != 0) fail_errno("VIDIOC_STREAMON");
    streaming_ = true;
  }
  UvcCamera(UvcCamera&& o) noexcept { swap(o); }
  UvcCamera& operator=(UvcCamera&& o) noexcept {
    if (this != &o) {
      close();
      swap(o);
    }
    return *this;
  }
  UvcCamera(const UvcCamera&) = delete;
  UvcCamera& operator=(const UvcCamera&) = delete;
  ~UvcCamera() { close(); }

  int width() const { return width_; }    ///< frame width [px]
  int height() const { return height_; }  ///< frame height [px]
  /// The pixel format streamed: "YUYV" or "MJPG".
  std::string format() const { return format_ == V4L2_PIX_FMT_YUYV ? "YUYV" : "MJPG"; }
  const std::string& card() const { return card_; }  ///< the driver's name for the camera

  /// The next frame as RGB. Throws IoError when none comes within `timeout_ms` or the device
  /// fails (unplugged).
  io::RgbImage grab(int timeout_ms = 1000) {
    pollfd p{fd_, POLLIN, 0};
    const int n = ::poll(&p, 1, timeout_ms);
    if (n == 0) fail_keep("no frame within " + std::to_string(timeout_ms) + " ms");
    if (n < 0) fail_keep(std::string("poll: ") + std::strerror(errno));
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(VIDIOC_DQBUF, &b) != 0)
      fail_keep(std::string("VIDIOC_DQBUF: ") + std::strerror(errno));
    io::RgbImage out;
    const auto* data = static_cast<const std::uint8_t*>(maps_.at(b.index).first);
    try {
      if (format_ == V4L2_PIX_FMT_YUYV) {
        if (b.bytesused < static_cast<std::uint32_t>(width_ * height_ * 2)) {
          throw IoError(device_, "a short YUYV frame (" + std::to_string(b.bytesused) + " bytes)");
        }
        yuyv_to_rgb(data, width_, height_, out);
      } else {
#if defined(TAXEL_DRIVERS_HAVE_JPEG)
        out = io::decode_jpeg(std::string_view(reinterpret_cast<const char*>(data), b.bytesused),
                              device_);
#endif
      }
    } catch (...) {
      (void)xioctl(VIDIOC_QBUF, &b);
      throw;
    }
    if (xioctl(VIDIOC_QBUF, &b) != 0)
      fail_keep(std::string("VIDIOC_QBUF: ") + std::strerror(errno));
    return out;
  }

 private:
  int xioctl(unsigned long request, void* arg) {
    int r;
    do {
      r = ::ioctl(fd_, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
  }
  void swap(UvcCamera& o) noexcept {
    std::swap(device_, o.device_);
    std::swap(card_, o.card_);
    std::swap(fd_, o.fd_);
    std::swap(maps_, o.maps_);
    std::swap(width_, o.width_);
    std::swap(height_, o.height_);
    std::swap(format_, o.format_);
    std::swap(streaming_, o.streaming_);
  }
  void close() noexcept {
    if (fd_ < 0) return;
    if (streaming_) {
      v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      (void)xioctl(VIDIOC_STREAMOFF, &type);
      streaming_ = false;
    }
    for (const auto& [p, len] : maps_) ::munmap(p, len);
    maps_.clear();
    ::close(fd_);
    fd_ = -1;
  }
  [[noreturn]] void fail(const std::string& why) {
    close();
    throw IoError(device_, why);
  }
  [[noreturn]] void fail_errno(const char* what) {
    fail(std::string(what) + ": " + std::strerror(errno));
  }
  [[noreturn]] void fail_keep(const std::string& why) { throw IoError(device_, why); }

  std::string device_, card_;
  int fd_ = -1;
  std::vector<std::pair<void*, std::size_t>> maps_;
  int width_ = 0, height_ = 0;
  std::uint32_t format_ = 0;
  bool streaming_ = false;
};

}  // namespace taxel::drivers
