#pragma once
// Images on disk and linear light. Blur and measurement happen in linear light (DESIGN.md): decode sRGB first.
#include <array>
#include <filesystem>

#include <opencv2/core.hpp>

#include "core/media.h"

namespace blurcue {

// Reads an image as 8-bit BGR or grey as stored; throws Error(kInput) naming the file when unreadable.
cv::Mat ReadImage(const std::filesystem::path& path, int flags = -1 /* cv::IMREAD_UNCHANGED */);
// What ReadImage checks before it decodes, without decoding: a regular file within the size limits, its header's
// size within them, and a JPEG or PNG whole (core/image_integrity.h). Throws Error(kInput) naming the file.
void RequireImageFileWhole(const std::filesystem::path& path);
// Writes atomically (core/atomic_file.h); creates the folder; throws naming the file on failure.
void WriteImage(const std::filesystem::path& path, const cv::Mat& image);
// What an image's name should end in, as the refusals say it.
inline constexpr const char* kImageNameHint = "name the file .png, .jpg, .tif or .bmp";
// Refuses (Error(kUsage), naming `option` and the path) a name WriteImage could not encode an image as ('x',
// 'x.xyz': no encoder for its extension, tried on one pixel), so a command says so before its work, not after.
void RequireImageName(const std::string& option, const std::filesystem::path& path);

// Opens `video` on an .avi at `path`: lossless FFV1 first (measurements are of edges a JPEG would soften), MJPEG,
// which every videoio writes, else. Returns the codec opened ("FFV1" or "MJPG"), or nullptr when neither opens.
const char* OpenLosslessVideo(media::VideoWriter& video, const std::filesystem::path& path, double fps, cv::Size size);

// sRGB transfer function, one channel value in [0, 1].
double SrgbToLinear(double v);
double LinearToSrgb(double v);
// The 256-entry table 8-bit sRGB -> linear [0, 1].
const std::array<float, 256>& SrgbDecodeTable();
// 8-bit sRGB (any channel count) -> CV_32F linear in [0, 1] with that table.
cv::Mat DecodeSrgb8(const cv::Mat& srgb8);
// CV_32F linear (clamped to [0, 1]) -> 8-bit sRGB, rounded.
cv::Mat EncodeSrgb8(const cv::Mat& linear);
// An 8-bit sRGB image resampled to `size` in linear light with an area (box) filter: each output pixel is the mean
// light of the input area it covers, so a downscale neither aliases fine detail nor darkens it (a gamma-encoded
// average would). 8-bit grey or BGR sRGB in and out.
cv::Mat ResampleSrgb8(const cv::Mat& srgb8, cv::Size size);
// 8-bit BGR/BGRA/grey -> one-channel 8-bit grey (as stored: gamma-encoded).
cv::Mat ToGrey8(const cv::Mat& image);
// The same into `grey`, whose buffer is reused when it has the size already (a video's frames).
void ToGrey8(const cv::Mat& image, cv::Mat& grey);

}  // namespace blurcue
