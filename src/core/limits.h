#pragma once
// Size limits every module shares: what a camera, a photo on disk or a rendered image may be at most. Values
// beyond them are refused with the limit named, before anything allocates or decodes.
#include <cstddef>
#include <cstdint>

namespace blurcue {

// The longest name, bytes: a protocol's, a block's, a factor's, a display profile's. One line in titles, records,
// exported tables and the report.
constexpr size_t kMaxNameChars = 100;

// The largest image side, px: every camera sold today fits (a 100 MP sensor is 11648 x 8736 px), and so does
// every stimulus; a larger value in a camera.json or a photo header is a typo or a hostile file.
constexpr int kMaxImageSidePx = 20000;

// The most pixels an image file may decode to: 120 M holds that 100 MP camera; 20000 x 20000 would need 1.2 GB
// as 8-bit BGR before any float copy.
constexpr int64_t kMaxImagePixels = 120'000'000;

// The largest image file read, bytes: a 120 Mpx 16-bit RGBA PNG stored raw is just under 1 GB.
constexpr int64_t kMaxImageFileBytes = int64_t(1) << 30;

}  // namespace blurcue
