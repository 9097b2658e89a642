#include "track/frames.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <regex>

#include <opencv2/imgproc.hpp>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>  // its constants (the reader: core/media.h)

#include "core/error.h"
#include "core/image.h"

namespace blurcue::track {
namespace {

// How far past a missing frame a sequence is looked at for more: a gap of up to this many frames is a missing
// frame, not the end.
constexpr int kGapLookahead = 16;

}  // namespace

std::vector<double> FrameSignature(const cv::Mat& bgr) {
  cv::Mat small;
  cv::resize(bgr, small, cv::Size(8, 8), 0, 0, cv::INTER_AREA);  // each cell's mean
  small.convertTo(small, CV_64F);
  std::vector<double> signature;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const double* p = small.ptr<double>(y) + x * small.channels();
      double sum = 0;
      for (int c = 0; c < small.channels(); ++c) sum += p[c];
      signature.push_back(std::round(100 * sum / small.channels()) / 100);
    }
  return signature;
}

double SignatureDistance(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

bool IsFramePattern(const std::string& input) { return input.find('%') != std::string::npos; }

std::filesystem::path PatternFile(const std::string& pattern, int index) {
  // One conversion of an int (%d, %4d, %04d), and "%%" for a literal percent sign: nothing that could read memory.
  static const std::regex kOne("^([^%]|%%)*%0?[0-9]{0,2}d([^%]|%%)*$");
  if (!std::regex_match(pattern, kOne))
    throw Error(ErrorKind::kUsage, "'" + pattern +
                                       "' must hold exactly one frame-number conversion like %04d (and %% for a "
                                       "literal percent sign)");
  char name[4096];
  const int n = std::snprintf(name, sizeof name, pattern.c_str(), index);
  if (n < 0 || n >= int(sizeof name)) throw Error(ErrorKind::kUsage, "'" + pattern + "' is too long");
  return name;
}

std::vector<std::filesystem::path> TakeInputFiles(const std::string& input) {
  if (!IsFramePattern(input)) return {input};
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (int i = 0, missing = 0; missing <= kGapLookahead; ++i) {
    const std::filesystem::path file = PatternFile(input, i);
    if (std::filesystem::exists(std::filesystem::symlink_status(file, error))) {
      files.push_back(file);
      missing = 0;
    } else {
      ++missing;
    }
  }
  return files;
}

FrameSource::FrameSource(const std::string& input, double fps) : input_(input), fps_(fps) {
  if (!(fps >= kMinFps && fps <= kMaxFps))
    throw Error(ErrorKind::kUsage, "a take's frame rate must be in [" + Num(kMinFps) + ", " + Num(kMaxFps) +
                                       "] frames per second, got " + Num(fps));
  if (IsFramePattern(input)) {
    pattern_ = input;
    const std::filesystem::path first = PatternFile(input, 0);
    if (!std::filesystem::exists(first))
      throw InputError(input, "no first frame: " + first.string() + " does not exist (frames are numbered from 0)");
    return;
  }
  if (!std::filesystem::exists(input)) throw InputError(input, "no such video file");
  // FFmpeg logs every damaged packet on stderr ("[ffv1 @ 0x...] Slice pointer chain broken"); the error this class
  // throws says it in one line instead. OpenCV reads the level once, at its first FFmpeg use; a user's own setting wins.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8" /* AV_LOG_QUIET */, 0);
  // FFmpeg reads every video Debian's videoio does; trying every backend (CAP_ANY) on a file that is not a video makes
  // GStreamer and the image-sequence reader print pages of warnings first. OpenCV's own log is quiet while opening.
  const cv::utils::logging::LogLevel level = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool opened = false;
  try {
    opened = video_.Open(input, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
    opened = false;
  }
  cv::utils::logging::setLogLevel(level);
  if (!opened) throw InputError(input, "OpenCV's videoio (FFmpeg) cannot open it as a video");
  const double rate = video_.Get(cv::CAP_PROP_FPS);
  if (rate >= kMinFps && rate <= kMaxFps) fps_ = rate;
  const double count = video_.Get(cv::CAP_PROP_FRAME_COUNT);
  expected_ = count > 0 && count < 1e7 ? static_cast<int>(std::lround(count)) : 0;
}

bool FrameSource::Next(cv::Mat* frame, int* index, double* time_s) {
  *index = next_;
  *time_s = next_ / fps_;
  if (pattern_) {
    const std::filesystem::path file = PatternFile(*pattern_, next_);
    if (!std::filesystem::exists(file)) {
      for (int k = 1; k <= kGapLookahead; ++k) {
        const std::filesystem::path later = PatternFile(*pattern_, next_ + k);
        if (std::filesystem::exists(later))
          throw InputError(file.string(), "frame " + std::to_string(next_) + " is missing but " + later.string() +
                                              " exists; the sequence has a gap");
      }
      return false;
    }
    *frame = ReadImage(file, 1 /* cv::IMREAD_COLOR */);
    ++next_;
    return true;
  }
  bool ok = false;
  try {
    ok = video_.Read(frame);
  } catch (const cv::Exception& e) {
    throw InputError(input_, "frame " + std::to_string(next_) + " cannot be decoded (" + e.err + ")");
  }
  if (!ok || frame->empty()) {
    if (expected_ > 0 && next_ < expected_)
      throw InputError(input_, "damaged or truncated: frame " + std::to_string(next_) + " of the " +
                                   std::to_string(expected_) + " its header promises cannot be read");
    return false;
  }
  ++next_;
  return true;
}

}  // namespace blurcue::track
