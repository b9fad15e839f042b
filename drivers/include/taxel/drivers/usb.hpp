// SPDX-License-Identifier: MIT
// A libusb transport: a device found by vendor/product id or by bus/address, one interface
// claimed, bulk IN/OUT with timeouts. A USB CDC-ACM data interface (a DSACON32m behind a
// USB-serial bridge) is two bulk endpoints, so the serial protocol runs over it directly.
#pragma once

#include <libusb.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "taxel/drivers/transport.hpp"

namespace taxel::drivers {

/// Which USB device and interface to use.
struct UsbSelector {
  std::optional<std::uint16_t> vendor_id{};   ///< match by vendor and product id
  std::optional<std::uint16_t> product_id{};  ///< (both or neither)
  std::optional<std::uint8_t> bus{};          ///< or by bus and address
  std::optional<std::uint8_t> address{};
  /// Interface to claim; by default the first with a bulk IN and a bulk OUT endpoint.
  std::optional<int> interface_number{};
};

/// A bulk-endpoint transport over libusb. Move-only; releases the interface and closes the
/// device on close() or destruction. An unplugged device reports `disconnected`.
class UsbTransport {
 public:
  explicit UsbTransport(UsbSelector selector) : sel_(selector) {
    if (sel_.vendor_id.has_value() != sel_.product_id.has_value() ||
        sel_.bus.has_value() != sel_.address.has_value() ||
        sel_.vendor_id.has_value() == sel_.bus.has_value()) {
      throw std::invalid_argument("UsbSelector: give vendor_id and product_id, or bus and address");
    }
  }
  UsbTransport(UsbTransport&& o) noexcept
      : sel_(o.sel_),
        ctx_(std::exchange(o.ctx_, nullptr)),
        handle_(std::exchange(o.handle_, nullptr)),
        iface_(o.iface_),
        ep_in_(o.ep_in_),
        ep_out_(o.ep_out_),
        in_packet_(o.in_packet_),
        pending_(std::move(o.pending_)),
        pending_at_(o.pending_at_) {}
  UsbTransport& operator=(UsbTransport&&) = delete;
  UsbTransport(const UsbTransport&) = delete;
  UsbTransport& operator=(const UsbTransport&) = delete;
  ~UsbTransport() {
    close();
    if (ctx_ != nullptr) libusb_exit(ctx_);
  }

  /// Finds the device, opens it, picks the bulk endpoints and claims the interface (detaching
  /// a kernel driver). Throws TransportError naming the device on failure.
  void open() {
    close();
    if (ctx_ == nullptr) check(libusb_init(&ctx_), "libusb_init");
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(ctx_, &list);
    if (n < 0) check(int(n), "libusb_get_device_list");
    libusb_device* found = nullptr;
    for (ssize_t i = 0; i < n && found == nullptr; ++i) {
      libusb_device_descriptor d{};
      if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
      const bool match = sel_.vendor_id
                             ? (d.idVendor == *sel_.vendor_id && d.idProduct == *sel_.product_id)
                             : (libusb_get_bus_number(list[i]) == *sel_.bus &&
                                libusb_get_device_address(list[i]) == *sel_.address);
      if (match) found = libusb_ref_device(list[i]);
    }
    libusb_free_device_list(list, 1);
    if (found == nullptr) {
      throw TransportError(TransportErrorKind::io, "usb: no device " + describe());
    }
    const int r = libusb_open(found, &handle_);
    if (r != 0) {
      libusb_unref_device(found);
      handle_ = nullptr;
      check(r, "libusb_open " + describe());
    }
    try {
      find_endpoints(found);
    } catch (...) {
      libusb_unref_device(found);
      close();
      throw;
    }
    libusb_unref_device(found);
    libusb_set_auto_detach_kernel_driver(handle_, 1);  // e.g. cdc_acm holds the interface
    const int c = libusb_claim_interface(handle_, iface_);
    if (c != 0) {
      libusb_close(handle_);
      handle_ = nullptr;
      check(c, "libusb_claim_interface " + std::to_string(iface_));
    }
  }

  /// Releases the interface and closes the device (idempotent).
  void close() noexcept {
    if (handle_ != nullptr) {
      libusb_release_interface(handle_, iface_);
      libusb_close(handle_);
      handle_ = nullptr;
    }
    pending_.clear();
    pending_at_ = 0;
  }
  /// True between open() and close() or a lost device.
  bool is_open() const noexcept { return handle_ != nullptr; }

  /// Bulk OUT of every byte; throws on timeout or a lost device.
  void write(std::span<const std::uint8_t> bytes, Timeout timeout) {
    require_open();
    while (!bytes.empty()) {
      int done = 0;
      const int r = libusb_bulk_transfer(handle_, ep_out_, const_cast<std::uint8_t*>(bytes.data()),
                                         static_cast<int>(bytes.size()), &done,
                                         static_cast<unsigned>(timeout.count()));
      if (r == LIBUSB_ERROR_TIMEOUT && done == 0) {
        throw TransportError(TransportErrorKind::timeout, "usb: bulk OUT timed out");
      }
      if (r != 0 && r != LIBUSB_ERROR_TIMEOUT) transfer_failed(r, "bulk OUT");
      bytes = bytes.subspan(std::size_t(done));
    }
  }

  /// Bytes from bulk IN (whole packets are buffered); 0 on timeout.
  std::size_t read(std::span<std::uint8_t> into, Timeout timeout) {
    require_open();
    if (into.empty()) return 0;
    if (pending_at_ == pending_.size()) {
      // Read whole packets: a transfer shorter than a packet could overflow.
      pending_.resize(std::max<std::size_t>(in_packet_, 64) * 16);
      int done = 0;
      const int r =
          libusb_bulk_transfer(handle_, ep_in_, pending_.data(), static_cast<int>(pending_.size()),
                               &done, static_cast<unsigned>(std::max<long>(timeout.count(), 1)));
      if (r != 0 && r != LIBUSB_ERROR_TIMEOUT) transfer_failed(r, "bulk IN");
      pending_.resize(std::size_t(done));
      pending_at_ = 0;
      if (done == 0) return 0;
    }
    const std::size_t n = std::min(into.size(), pending_.size() - pending_at_);
    std::copy_n(pending_.begin() + long(pending_at_), n, into.begin());
    pending_at_ += n;
    return n;
  }

 private:
  std::string describe() const {
    char buf[64];
    if (sel_.vendor_id) {
      std::snprintf(buf, sizeof buf, "%04x:%04x", *sel_.vendor_id, *sel_.product_id);
    } else {
      std::snprintf(buf, sizeof buf, "at bus %u address %u", unsigned(*sel_.bus),
                    unsigned(*sel_.address));
    }
    return buf;
  }
  void find_endpoints(libusb_device* dev) {
    libusb_config_descriptor* cfg = nullptr;
    check(libusb_get_active_config_descriptor(dev, &cfg), "libusb_get_active_config_descriptor");
    bool ok = false;
    for (int i = 0; i < cfg->bNumInterfaces && !ok; ++i) {
      const libusb_interface& itf = cfg->interface[i];
      for (int a = 0; a < itf.num_altsetting && !ok; ++a) {
        const libusb_interface_descriptor& d = itf.altsetting[a];
        if (sel_.interface_number && d.bInterfaceNumber != *sel_.interface_number) continue;
        int in = -1, out = -1, in_size = 0;
        for (int e = 0; e < d.bNumEndpoints; ++e) {
          const libusb_endpoint_descriptor& ep = d.endpoint[e];
          if ((ep.bmAttributes & 0x03) != LIBUSB_TRANSFER_TYPE_BULK) continue;
          if (ep.bEndpointAddress & LIBUSB_ENDPOINT_IN) {
            if (in < 0) {
              in = ep.bEndpointAddress;
              in_size = ep.wMaxPacketSize;
            }
          } else if (out < 0) {
            out = ep.bEndpointAddress;
          }
        }
        if (in >= 0 && out >= 0) {
          iface_ = d.bInterfaceNumber;
          ep_in_ = static_cast<unsigned char>(in);
          ep_out_ = static_cast<unsigned char>(out);
          in_packet_ = std::size_t(in_size);
          ok = true;
        }
      }
    }
    libusb_free_config_descriptor(cfg);
    if (!ok) {
      throw TransportError(
          TransportErrorKind::io,
          "usb: " + describe() + " has no interface with bulk IN and OUT" +
              (sel_.interface_number ? " (interface " + std::to_string(*sel_.interface_number) + ")"
                                     : std::string()));
    }
  }
  void require_open() const {
    if (handle_ == nullptr) throw TransportError(TransportErrorKind::not_open, "usb: not open");
  }
  [[noreturn]] void transfer_failed(int r, const char* what) {
    const bool gone = r == LIBUSB_ERROR_NO_DEVICE || r == LIBUSB_ERROR_IO || r == LIBUSB_ERROR_PIPE;
    close();
    throw TransportError(gone ? TransportErrorKind::disconnected : TransportErrorKind::io,
                         std::string("usb: ") + what + ": " + libusb_error_name(r));
  }
  static void check(int r, const std::string& what) {
    if (r < 0) {
      throw TransportError(
          r == LIBUSB_ERROR_NO_DEVICE ? TransportErrorKind::disconnected : TransportErrorKind::io,
          "usb: " + what + ": " + libusb_error_name(r));
    }
  }

  UsbSelector sel_;
  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int iface_ = 0;
  unsigned char ep_in_ = 0, ep_out_ = 0;
  std::size_t in_packet_ = 64;
  std::vector<std::uint8_t> pending_;
  std::size_t pending_at_ = 0;
};

static_assert(Transport<UsbTransport>);

}  // namespace taxel::drivers
