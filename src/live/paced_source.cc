#include "live/paced_source.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <regex>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>  // its constants (the reader: core/media.h)

#include "core/typed.h"

namespace blurcue::live {

std::string CameraDevice(const std::string& input) {
  static const std::regex kDevice("^/dev/video([0-9]{1,3})$"), kIndex("^[0-9]{1,3}$");
  std::smatch m;
  if (std::regex_match(input, m, kDevice)) return input;
  if (std::regex_match(input, kIndex)) return "/dev/video" + std::to_string(std::stoi(input));
  return "";
}

PacedSource::PacedSource(const std::string& input, double fps, int max_frames)
    : input_(input), device_(CameraDevice(input)), max_frames_(max_frames) {
  if (fps != 0 && !(fps >= track::kMinFps && fps <= track::kMaxFps))
    throw Error(ErrorKind::kUsage, "--fps: must be in [" + Num(track::kMinFps) + ", " + Num(track::kMaxFps) +
                                       "] frames per second, got " + Num(fps));
  if (device_.empty()) {
    file_ = std::make_unique<track::FrameSource>(input, fps > 0 ? fps : 30);
    fps_ = fps > 0 ? fps : file_->fps();
    return;
  }
  if (fps != 0)
    throw Error(ErrorKind::kUsage, "--fps " + Num(fps) + ": a camera (" + device_ +
                                       ") delivers frames at its own rate; --fps paces a video or an image sequence");
  std::error_code error;
  if (!std::filesystem::exists(device_, error))
    throw InputError(device_, "no camera there (no such V4L2 device" +
                                  std::string(device_ == input ? "" : "; INPUT " + Echo(input) + " names it") + ")");
  camera_ = std::make_unique<media::VideoReader>();
  const cv::utils::logging::LogLevel level = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool opened = false;
  try {
    opened = camera_->Open(device_, cv::CAP_V4L2);
  } catch (const cv::Exception&) {
    opened = false;
  }
  cv::utils::logging::setLogLevel(level);
  if (!opened) throw InputError(device_, "OpenCV's videoio (V4L2) cannot open it as a camera (busy, or not a camera)");
}

PacedSource::PacedSource(const std::string& device, std::unique_ptr<media::VideoReader> reader, int max_frames)
    : input_(device), device_(device), max_frames_(max_frames), camera_(std::move(reader)) {}

PacedSource::~PacedSource() { Stop(); }

int PacedSource::expected_frames() const { return file_ ? file_->expected_frames() : 0; }

void PacedSource::Start(FrameMailbox* mailbox, Clock::time_point start) {
  auto guarded = [this, mailbox](auto&& body) {
    try {
      body();
    } catch (const Error& e) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = e;
      }
      mailbox->Close(e.what(), true);
    } catch (const std::exception& e) {  // OpenCV's own, from a driver: one line, not a crash of the thread
      const Error wrapped(ErrorKind::kInput, (device_.empty() ? input_ : device_) + ": " + e.what());
      {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = wrapped;
      }
      mailbox->Close(wrapped.what(), true);
    }
  };
  if (!file_) {
    thread_ = std::thread([this, mailbox, guarded] { guarded([&] { ReadCamera(mailbox); }); });
    return;
  }
  if (!decoded_end_) decoder_ = std::thread([this] { DecodeVideo(); });  // else preloaded whole
  thread_ = std::thread([this, mailbox, start, guarded] { guarded([&] { PaceVideo(mailbox, start); }); });
}

void PacedSource::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  ahead_changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (decoder_.joinable()) decoder_.join();
}

std::optional<Error> PacedSource::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

bool PacedSource::WaitUntil(Clock::time_point due) {
  std::unique_lock<std::mutex> lock(mutex_);
  return !wake_.wait_until(lock, due, [this] { return stop_.load(); });
}

void PacedSource::DecodeVideo() { DecodeFrames(kDecodeAhead, 0); }

int PacedSource::FramesToPreload() const {
  const int most = max_frames_ > 0 ? max_frames_ : std::numeric_limits<int>::max();
  if (file_->is_video()) return std::min(file_->expected_frames(), most);
  int frames = 0;
  std::error_code error;
  while (frames < most && std::filesystem::exists(track::PatternFile(input_, frames), error)) ++frames;
  return frames;
}

Error PacedSource::TooMuchToPreload(int frames, bool known, double frame_mb, double max_mb) const {
  // Round numbers for a person: whole frames and MB, a frame's MB to a tenth.
  const int fit = int(max_mb / frame_mb);
  char each[96];
  std::snprintf(each, sizeof each, "%.1f MB each%s", frame_mb,
                known ? (" (" + std::to_string(int(std::lround(frames * frame_mb))) + " MB)").c_str() : "");
  return Error(ErrorKind::kUsage, input_ + ": --preload would hold " +
                                      (known ? "its " + std::to_string(frames) : "more than " + std::to_string(fit)) +
                                      " frames decoded, " + each + ": more than the " + Num(max_mb) +
                                      " MB it may hold (" + std::to_string(fit) + " frames); give --frames " +
                                      std::to_string(fit) + ", or leave --preload out");
}

void PacedSource::CheckPreloadFits(cv::Size frame_size, double max_mb) const {
  if (!file_)
    throw Error(ErrorKind::kUsage, "--preload: " + device_ + " is a camera, which hands over its frames decoded already; "
                                   "--preload is for a video or an image sequence");
  // Refused before a frame is decoded (it was found after decoding up to the limit: 12 s and 2 GB for a sequence of
  // 900 frames).
  const double frame_mb = 1e-6 * 3.0 * frame_size.area();
  if (const int frames = FramesToPreload(); frame_mb > 0 && frames * frame_mb > max_mb)
    throw TooMuchToPreload(frames, true, frame_mb, max_mb);
}

double PacedSource::Preload(cv::Size frame_size, double max_mb, const std::atomic<int>* interrupt) {
  CheckPreloadFits(frame_size, max_mb);
  const auto t0 = Clock::now();
  interrupt_ = interrupt;
  DecodeFrames(0, max_mb);
  interrupt_ = nullptr;
  preloaded_frames_ = int(ahead_.size());
  for (const LiveFrame& f : ahead_) preloaded_mb_ += 1e-6 * double(f.image.total() * f.image.elemSize());
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool PacedSource::DecodeFrames(int ahead_limit, double max_mb) {
  int read = 0;
  double held_mb = 0;
  std::string why, too_much;
  std::optional<Error> error;
  try {
    while (true) {
      LiveFrame frame;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ahead_changed_.wait(lock, [&] { return stop_ || ahead_limit == 0 || int(ahead_.size()) < ahead_limit; });
        if (stop_) return false;
        if (!spare_.empty()) {
          frame.image = std::move(spare_.back());
          spare_.pop_back();
        }
      }
      if (interrupt_ && *interrupt_ != 0) {
        why = "interrupted while preloading, after " + std::to_string(read) + " frames";
        break;
      }
      if (max_frames_ > 0 && read == max_frames_) {
        why = std::to_string(read) + " frames read (--frames)";
        break;
      }
      if (!file_->Next(&frame.image, &frame.index, &frame.time_s)) {
        why = input_ + " ended after " + std::to_string(read) + " frames";
        break;
      }
      ++read;
      const double frame_mb = 1e-6 * double(frame.image.total() * frame.image.elemSize());
      held_mb += frame_mb;
      // A video whose header gives no count, or frames larger than the camera's: found as they are decoded.
      if (max_mb > 0 && held_mb > max_mb) {
        too_much = TooMuchToPreload(read, false, frame_mb, max_mb).what();
        break;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      ahead_.push_back(std::move(frame));
      ahead_changed_.notify_all();
    }
  } catch (const Error& e) {
    error = e;
    why = e.what();
  } catch (const std::exception& e) {
    error = Error(ErrorKind::kInput, input_ + ": " + e.what());
    why = error->what();
  }
  if (!too_much.empty()) throw Error(ErrorKind::kUsage, too_much);  // only Preload sets a limit
  std::lock_guard<std::mutex> lock(mutex_);
  decoded_end_ = true;
  end_why_ = why;
  end_error_ = error;
  ahead_changed_.notify_all();
  return true;
}

void PacedSource::PaceVideo(FrameMailbox* mailbox, Clock::time_point start) {
  LiveFrame frame;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ahead_changed_.wait(lock, [this] { return stop_ || !ahead_.empty() || decoded_end_; });
      if (stop_) return;
      if (ahead_.empty()) {  // the decoder is done and every frame it decoded was posted
        if (end_error_) {
          error_ = end_error_;
          lock.unlock();
          mailbox->Close(end_why_, true);
        } else {
          lock.unlock();
          mailbox->Close(end_why_, false);
        }
        return;
      }
      if (!frame.image.empty()) spare_.push_back(std::move(frame.image));
      frame = std::move(ahead_.front());
      ahead_.pop_front();
      ahead_changed_.notify_all();
    }
    // Posted at its time, or at once when it was decoded later than that (then it arrives late, and the log's
    // arrival times show it).
    const auto due = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                 frame.index / fps_));
    if (!WaitUntil(due)) return;
    frame.arrival = Clock::now();
    mailbox->Post(frame);
  }
}

void PacedSource::ReadCamera(FrameMailbox* mailbox) {
  LiveFrame frame;
  const Clock::time_point start = Clock::now();
  int read = 0;
  while (!stop_) {
    if (max_frames_ > 0 && read == max_frames_) {
      mailbox->Close(std::to_string(read) + " frames read (--frames)", false);
      return;
    }
    if (!camera_->Read(&frame.image) || frame.image.empty())
      throw InputError(device_, "the camera stopped delivering frames after " + std::to_string(read) + " frames");
    frame.arrival = Clock::now();
    frame.index = read++;
    frame.time_s = std::chrono::duration<double>(frame.arrival - start).count();
    mailbox->Post(frame);
  }
}

}  // namespace blurcue::live
