// SPDX-License-Identifier: MIT
// Fuzzes the contacts CSV reader with arbitrary bytes after an optional valid header (the
// first byte picks). It must throw taxel::IoError or return contacts with finite positions
// that encode and read back identically, and that a ContactCloud accepts or rejects cleanly.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/fusion/contact_cloud.hpp>
#include <taxel/io/contacts_csv.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* kHeads[] = {
      "time,x,y,z,cxx,cxy,cxz,cyy,cyz,czz,nx,ny,nz,pressure,normal_sigma,footprint_sigma\n",
      "x,y,z\n", ""};
  std::string text = kHeads[data[0] % 3];
  text.append(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const auto contacts = taxel::io::parse_contacts_csv(text, "<fuzz>");
    for (const auto& c : contacts) {
      if (!c.position.allFinite()) std::abort();
    }
    const auto back = taxel::io::parse_contacts_csv(taxel::io::encode_contacts_csv(contacts));
    if (back.size() != contacts.size()) std::abort();
    for (std::size_t i = 0; i < back.size(); ++i) {
      if (back[i].position != contacts[i].position ||
          back[i].normal.has_value() != contacts[i].normal.has_value()) {
        std::abort();
      }
    }
    taxel::fusion::ContactCloud<> cloud;
    const auto counts = cloud.insert(std::span(contacts));
    if (counts.added + counts.fused + counts.rejected != contacts.size()) std::abort();
  } catch (const taxel::IoError&) {
  }
  return 0;
}
