#include "core/image_integrity.h"

#include <cstdint>
#include <cstring>
#include <string>

#include <zlib.h>

#include "core/error.h"

namespace blurcue {
namespace {

uint32_t Be(std::string_view b, size_t at, int n) {
  uint32_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | static_cast<unsigned char>(b[at + size_t(i)]);
  return v;
}

std::string Hex2(unsigned v) {
  char text[8];
  std::snprintf(text, sizeof text, "%02X", v & 0xffu);
  return text;
}

// JPEG (ITU T.81 B.1): marker segments, each scan's entropy-coded data up to the next marker that is not a restart
// (FFD0-FFD7) or a stuffed zero (FF00), and at last EOI. A file cut anywhere inside loses its EOI.
void RequireIntactJpeg(const std::filesystem::path& path, std::string_view b) {
  const std::string where = path.string();
  const std::string whole = "; the file is " + std::to_string(b.size()) + " bytes";
  size_t i = 2;  // after SOI
  bool scanned = false;
  while (i < b.size()) {
    if (static_cast<unsigned char>(b[i]) != 0xff)
      throw InputError(where, "damaged JPEG: byte " + std::to_string(i) + " should start a marker (FF), got " +
                                  Hex2(static_cast<unsigned char>(b[i])) + whole);
    if (i + 1 >= b.size()) break;
    const unsigned marker = static_cast<unsigned char>(b[i + 1]);
    if (marker == 0xff) {  // fill byte before a marker
      ++i;
      continue;
    }
    if (marker == 0xd9) {
      if (!scanned)
        throw InputError(where, "damaged JPEG: it ends (FFD9 at byte " + std::to_string(i) + ") before any image scan");
      return;  // EOI: whole
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) {  // no length
      i += 2;
      continue;
    }
    if (marker == 0xd8 || marker == 0x00)
      throw InputError(where, "damaged JPEG: unexpected marker FF" + Hex2(marker) + " at byte " + std::to_string(i) +
                                  whole);
    if (i + 4 > b.size()) break;
    const size_t length = Be(b, i + 2, 2);
    if (length < 2 || i + 2 + length > b.size())
      throw InputError(where, "damaged or truncated JPEG: the FF" + Hex2(marker) + " segment at byte " +
                                  std::to_string(i) + " says it is " + std::to_string(length) +
                                  " bytes, past the end of the file" + whole);
    i += 2 + length;
    if (marker != 0xda) continue;
    // Entropy-coded data: up to the next FF that is neither a stuffed zero nor a restart marker.
    scanned = true;
    for (;;) {
      const void* ff = std::memchr(b.data() + i, 0xff, b.size() - i);
      if (!ff) {
        i = b.size();
        break;
      }
      i = size_t(static_cast<const char*>(ff) - b.data());
      if (i + 1 >= b.size()) {
        i = b.size();
        break;
      }
      const unsigned next = static_cast<unsigned char>(b[i + 1]);
      if (next == 0x00 || (next >= 0xd0 && next <= 0xd7)) {
        i += 2;
        continue;
      }
      break;  // a marker (or fill FFs before one)
    }
  }
  throw InputError(where, std::string("truncated JPEG: the file ends (at byte ") + std::to_string(b.size()) + ") " +
                              (scanned ? "inside its image data" : "before its image data") +
                              ", without the end-of-image marker FFD9; the image is cut short");
}

// PNG (ISO 15948 5.3): chunks of length, type, data and a CRC-32 of type and data, from IHDR to IEND.
void RequireIntactPng(const std::filesystem::path& path, std::string_view b) {
  const std::string where = path.string();
  size_t i = 8;
  while (i + 12 <= b.size()) {
    const uint32_t length = Be(b, i, 4);
    const std::string type(b.substr(i + 4, 4));
    bool printable = true;
    for (char c : type) printable = printable && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'));
    const std::string name = printable ? "'" + type + "'" : "(unreadable type)";
    if (length > 0x7fffffffu || i + 12 + length > b.size())
      throw InputError(where, "truncated PNG: chunk " + name + " at byte " + std::to_string(i) + " says it holds " +
                                  std::to_string(length) + " bytes, past the end of the " +
                                  std::to_string(b.size()) + "-byte file; the image is cut short");
    const uint32_t stored = Be(b, i + 8 + length, 4);
    // zlib's crc32 in pieces: a chunk may be longer than its uInt length argument on some platforms.
    uLong crc = crc32(0L, Z_NULL, 0);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(b.data() + i + 4), uInt(4 + length));
    if (uint32_t(crc) != stored)
      throw InputError(where, "damaged PNG: chunk " + name + " at byte " + std::to_string(i) +
                                  " fails its CRC-32 check (its bytes were changed)");
    if (type == "IEND") return;
    i += 12 + size_t(length);
  }
  throw InputError(where, "truncated PNG: the file ends (at byte " + std::to_string(b.size()) +
                              ") before its IEND chunk; the image is cut short");
}

}  // namespace

void RequireIntactImage(const std::filesystem::path& path, std::string_view bytes) {
  static const char kPng[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPng, 8) == 0) return RequireIntactPng(path, bytes);
  if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xff &&
      static_cast<unsigned char>(bytes[1]) == 0xd8 && static_cast<unsigned char>(bytes[2]) == 0xff)
    return RequireIntactJpeg(path, bytes);
}

bool DecoderSaysDamaged(std::string_view text) {
  // Line by line: libjpeg's "Corrupt JPEG data: N extraneous bytes before marker 0xd9" comes from cameras that pad
  // their files, on images that decode whole; its other corrupt-data warnings (bad Huffman code, premature end of
  // data segment) mean pixels were invented.
  while (!text.empty()) {
    const size_t end = text.find_first_of("\n;");
    const std::string_view line = text.substr(0, end);
    for (const char* words : {"Premature end", "premature end", "Corrupt JPEG data", "CRC error", "Not enough image data"})
      if (line.find(words) != std::string_view::npos && line.find("extraneous bytes") == std::string_view::npos)
        return true;
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return false;
}

}  // namespace blurcue
