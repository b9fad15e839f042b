// SPDX-License-Identifier: MIT
// UsbTransport and DsaconDevice against an emulated USB device: umockdev provides the sysfs
// entry and the /dev/bus/usb node that libusb enumerates and opens, and an in-process handler
// answers the usbfs ioctls (URB submit/reap/discard on a bulk IN and a bulk OUT endpoint),
// speaking the DSACON32m protocol through the software controller. Runs under
// umockdev-wrapper (it preloads umockdev's libc interposer); not under AddressSanitizer.
#include <sys/ioctl.h>
// sys/ioctl.h first: linux/usbdevice_fs.h uses its _IO macros.
#include <linux/usbdevice_fs.h>
#include <umockdev.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <taxel/drivers/dsacon_device.hpp>
#include <taxel/drivers/dsacon_emulator.hpp>
#include <taxel/drivers/usb.hpp>

namespace td = taxel::drivers;

namespace {

// A bulk device 1234:5678: one vendor-specific interface, bulk IN 0x81, bulk OUT 0x02, 64-byte
// packets. Device descriptor, then the configuration with its interface and endpoints.
constexpr const char* kDevice =
    "P: /devices/usb1\n"
    "N: bus/usb/001/001\n"
    "E: SUBSYSTEM=usb\n"
    "E: DRIVER=usb\n"
    "E: BUSNUM=001\n"
    "E: DEVNUM=001\n"
    "E: DEVNAME=/dev/bus/usb/001/001\n"
    "E: DEVTYPE=usb_device\n"
    "A: busnum=1\\n\n"
    "A: devnum=1\\n\n"
    "A: bConfigurationValue=1\\n\n"
    "A: speed=12\\n\n"
    "H: descriptors="
    "120100020000004034127856000101020301"  // device
    "090220000101008032"                    // configuration, 32 bytes in all
    "0904000002ff000000"                    // interface 0: 2 endpoints, vendor class
    "07058102400000"                        // bulk IN 0x81, 64 bytes
    "07050202400000\n";                     // bulk OUT 0x02, 64 bytes

// The emulated device: usbfs semantics over the software controller.
struct UsbDsacon {
  td::DsaconEmulator controller;
  std::deque<std::uint8_t> to_host;           // device -> host bytes not yet delivered
  std::deque<UMockdevIoctlData*> completed;   // URBs ready to reap
  std::deque<UMockdevIoctlData*> waiting_in;  // IN URBs waiting for data
  std::chrono::steady_clock::time_point next_frame = std::chrono::steady_clock::now();
  std::atomic<bool> unplugged{false};
  std::atomic<int> out_urbs{0};

  explicit UsbDsacon(td::EmulatorConfig cfg)
      : controller(std::move(cfg), [this](std::uint64_t i) {
          std::vector<std::uint16_t> v(controller.cells());
          for (std::size_t k = 0; k < v.size(); ++k) v[k] = std::uint16_t((k + i) % 4096);
          return v;
        }) {}

  // Fills waiting IN URBs from the byte queue (one URB per call), streaming frames when due.
  void pump() {
    if (controller.streaming() && std::chrono::steady_clock::now() >= next_frame) {
      const auto f = controller.next_frame();
      to_host.insert(to_host.end(), f.begin(), f.end());
      next_frame = std::chrono::steady_clock::now() + std::chrono::milliseconds(2);
    }
    if (waiting_in.empty() || to_host.empty()) return;
    UMockdevIoctlData* d = waiting_in.front();
    waiting_in.pop_front();
    auto* urb = reinterpret_cast<usbdevfs_urb*>(d->data);
    const auto n = std::min<std::size_t>(std::size_t(urb->buffer_length), to_host.size());
    // In-process: the URB's buffer pointer is valid here.
    std::copy_n(to_host.begin(), n, static_cast<std::uint8_t*>(urb->buffer));
    to_host.erase(to_host.begin(), to_host.begin() + long(n));
    urb->actual_length = int(n);
    urb->status = 0;
    completed.push_back(d);
  }
};

gboolean handle_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer user) {
  auto* dev = static_cast<UsbDsacon*>(user);
  const unsigned long request = umockdev_ioctl_client_get_request(client);
  UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
  if (dev->unplugged) {
    // The URBs in flight die with the device.
    for (auto* d : dev->waiting_in) umockdev_ioctl_data_unref(d);
    for (auto* d : dev->completed) umockdev_ioctl_data_unref(d);
    dev->waiting_in.clear();
    dev->completed.clear();
    dev->to_host.clear();
    umockdev_ioctl_client_complete(client, -1, ENODEV);
    return TRUE;
  }
  switch (request) {
    case USBDEVFS_GET_CAPABILITIES: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), nullptr);
      *reinterpret_cast<guint32*>(d->data) =
          USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
          USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
      umockdev_ioctl_data_unref(d);
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE:
    case USBDEVFS_CLEAR_HALT:
    case USBDEVFS_RESET:
    case USBDEVFS_RESETEP:
    case USBDEVFS_SETINTERFACE:
    case USBDEVFS_DISCONNECT_CLAIM:  // claim, detaching a kernel driver if one were bound
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    case USBDEVFS_GETDRIVER:  // no kernel driver bound
    case USBDEVFS_IOCTL:      // driver disconnect/connect: none to act on
      umockdev_ioctl_client_complete(client, -1, ENODATA);
      return TRUE;
    case USBDEVFS_SUBMITURB: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
      auto* urb = reinterpret_cast<usbdevfs_urb*>(d->data);
      if (urb->type != USBDEVFS_URB_TYPE_BULK) {
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return TRUE;
      }
      if (urb->endpoint == 0x02) {
        const auto* bytes = static_cast<const std::uint8_t*>(urb->buffer);
        const auto reply = dev->controller.receive(
            std::span<const std::uint8_t>(bytes, std::size_t(urb->buffer_length)));
        dev->to_host.insert(dev->to_host.end(), reply.begin(), reply.end());
        urb->actual_length = urb->buffer_length;
        urb->status = 0;
        dev->completed.push_back(d);
        ++dev->out_urbs;
      } else if (urb->endpoint == 0x81) {
        dev->waiting_in.push_back(d);
      } else {
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, -1, ENOENT);
        return TRUE;
      }
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    case USBDEVFS_DISCARDURB: {
      const auto addr = reinterpret_cast<gulong>(*reinterpret_cast<void**>(arg->data));
      for (auto it = dev->waiting_in.begin(); it != dev->waiting_in.end(); ++it) {
        if ((*it)->client_addr == addr) {
          auto* urb = reinterpret_cast<usbdevfs_urb*>((*it)->data);
          urb->status = -ENOENT;
          urb->actual_length = 0;
          dev->completed.push_back(*it);
          dev->waiting_in.erase(it);
          umockdev_ioctl_client_complete(client, 0, 0);
          return TRUE;
        }
      }
      umockdev_ioctl_client_complete(client, -1, EINVAL);
      return TRUE;
    }
    case USBDEVFS_REAPURB:
    case USBDEVFS_REAPURBNDELAY: {
      dev->pump();
      if (dev->completed.empty()) {
        umockdev_ioctl_client_complete(client, -1, EAGAIN);
        return TRUE;
      }
      UMockdevIoctlData* d = dev->completed.front();
      dev->completed.pop_front();
      UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), nullptr);
      umockdev_ioctl_data_set_ptr(ptr, 0, d);
      umockdev_ioctl_data_unref(ptr);
      umockdev_ioctl_data_unref(d);
      umockdev_ioctl_client_complete(client, 0, 0);
      return TRUE;
    }
    default:
      fprintf(stderr, "unhandled ioctl %lx\n", request);
      return FALSE;
  }
}

struct Testbed {
  UMockdevTestbed* bed = umockdev_testbed_new();
  UMockdevIoctlBase* handler = umockdev_ioctl_base_new();
  UsbDsacon device;

  explicit Testbed(td::EmulatorConfig cfg) : device(std::move(cfg)) {
    g_signal_connect(handler, "handle-ioctl", G_CALLBACK(handle_ioctl), &device);
    REQUIRE(umockdev_testbed_attach_ioctl(bed, "/dev/bus/usb/001/001", handler, nullptr));
    GError* err = nullptr;
    if (!umockdev_testbed_add_from_string(bed, kDevice, &err))
      FAIL("umockdev: " << (err ? err->message : "add_from_string failed"));
  }
  ~Testbed() {
    g_object_unref(handler);
    g_object_unref(bed);
  }
};

}  // namespace

TEST_CASE("UsbTransport: a DSACON32m on bulk endpoints under umockdev", "[drivers][usb]") {
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload == nullptr || std::strstr(preload, "libumockdev-preload") == nullptr) {
    WARN("SKIPPED: run under umockdev-wrapper (Debian package umockdev)");
    return;
  }
  td::EmulatorConfig cfg;
  cfg.period_ms = 2.0;
  Testbed tb(cfg);

  SECTION("open by id and by bus/address, handshake, frames, stop") {
    td::DsaconDevice dev(td::UsbTransport({.vendor_id = 0x1234, .product_id = 0x5678}),
                         {.reply_timeout = td::Timeout(1000)});
    dev.open();
    CHECK(dev.cells() == 486);
    CHECK(dev.matrices().size() == 6);
    dev.start();
    for (int k = 0; k < 10; ++k) {
      const auto f = dev.read_frame();
      REQUIRE(f);
      const std::uint64_t i = f->device_time_ms / 2;
      CHECK(f->matrices[0](0, 0) == std::uint16_t(i % 4096));
      CHECK(f->matrices[5](12, 5) == std::uint16_t((485 + i) % 4096));
    }
    dev.stop();
    CHECK_FALSE(tb.device.controller.streaming());
    dev.close();

    td::UsbTransport by_bus({.bus = 1, .address = 1});
    by_bus.open();
    CHECK(by_bus.is_open());
    std::uint8_t buf[16];
    CHECK(by_bus.read(buf, td::Timeout(20)) == 0);  // a silent device: a timeout, no error
  }
  SECTION("a device that is not there, and bad selectors") {
    td::UsbTransport missing({.vendor_id = 0x1234, .product_id = 0x9999});
    CHECK_THROWS_WITH(missing.open(), Catch::Contains("no device 1234:9999"));
    CHECK_THROWS_AS(td::UsbTransport({.vendor_id = 0x1234}), std::invalid_argument);
  }
  SECTION("hot unplug while streaming: reported, never half a frame") {
    td::DsaconDevice dev(td::UsbTransport({.vendor_id = 0x1234, .product_id = 0x5678}));
    dev.open();
    dev.start();
    REQUIRE(dev.read_frame());
    tb.device.unplugged = true;
    bool reported = false;
    try {
      for (int k = 0; k < 1000; ++k) {
        const auto f = dev.read_frame();
        if (f) REQUIRE(f->matrices.size() == 6);  // frames already received are whole
      }
    } catch (const td::TransportError& e) {
      reported = e.kind() == td::TransportErrorKind::disconnected;
    }
    CHECK(reported);
    CHECK_FALSE(dev.is_open());
    // Plugged back in: the device reopens.
    tb.device.unplugged = false;
    dev.open();
    CHECK(dev.cells() == 486);
  }
}
