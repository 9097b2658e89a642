#include "stimulus/stimulus.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "core/error.h"
#include "core/image.h"
#include "scene/stimuli.h"
#include "stimulus/internal.h"
#include "stimulus/tracked_take.h"
#include "stimulus/video_take.h"

namespace blurcue::stimulus {

namespace {

// A video scene's calibration as the trials are described with it: its first frame with a pose.
calib::SceneCalib FirstPosedCalib(const protocol::Protocol& protocol) {
  TrackedTake take;
  try {
    take = LoadTrackedTake(protocol.scene.track);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, "/scene/track"), e.what());
  }
  for (const TrackedFrame& f : take.frames)
    if (f.calib) return *f.calib;
  throw InputError(At(protocol, "/scene/track"), "no frame has a pose");  // LoadTrackedTake refuses it already
}

}  // namespace

std::optional<calib::SceneCalib> LoadProtocolScene(const protocol::Protocol& protocol) {
  if (protocol.scene.IsVideo()) {
    return FirstPosedCalib(protocol);
  }
  if (protocol.scene.calib.empty()) {
    if (protocol.content.type == protocol::ContentType::kPicture) return std::nullopt;
    throw InputError(At(protocol, "/scene/calib"), "a " + protocol::ToString(protocol.content.type) + " needs a calibration");
  }
  try {
    return calib::LoadSceneCalib(protocol.scene.calib);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, "/scene/calib"), std::string(kNotACalibration) + e.what());
  }
}

namespace {

// Reads the image a field names, as 8-bit with 1, 3 or 4 channels; every failure is an input error naming the
// protocol field first. `max_aspect`: how much wider than tall (or taller than wide) its use can show it.
cv::Mat ReadFieldImage(const protocol::Protocol& protocol, const std::string& pointer, const std::filesystem::path& path,
                       int flags, double max_aspect, int max_side_px) {
  cv::Mat image;
  try {
    image = ReadImage(path, flags);
    if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1 / 257.0);
    else if (image.depth() == CV_32F || image.depth() == CV_64F) image.convertTo(image, CV_8U, 255);
  } catch (const std::exception& e) {  // Error, cv::Exception, std::filesystem::filesystem_error
    throw InputError(At(protocol, pointer), e.what());
  }
  const int w = image.cols, h = image.rows;
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw InputError(At(protocol, pointer), path.string() + ": an image must be 8 or 16 bit grey, colour or colour "
                                                            "with alpha");
  if (w < 2 || h < 2 || w > max_side_px || h > max_side_px || w > max_aspect * h || h > max_aspect * w)
    throw InputError(At(protocol, pointer), path.string() + ": is " + std::to_string(w) + " x " + std::to_string(h) +
                                                " px; it must be 2 to " + std::to_string(max_side_px) +
                                                " px a side and at most " + std::to_string(int(max_aspect)) +
                                                " times as wide as tall or as tall as wide");
  return image;
}

// Photos up to 16384 px a side (more than a 45 MP camera's 8256); a ball's or card's texture needs far less than
// 8192.
constexpr int kMaxPhotoSidePx = 16384, kMaxTextureSidePx = 8192;

}  // namespace

StimulusImages LoadStimulusImages(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene) {
  StimulusImages images;
  // A depth matching with real photos shows no scene photo (the protocol has no scene).
  const bool board_free = protocol.scene.ShowsBoardFree();
  const std::string photo_field = board_free ? "/scene/board_free" : "/scene/background";
  const auto& photo_path = protocol.scene.ShownPhoto();
  if (protocol.scene.IsVideo()) {
    // Every frame a trial can show, decoded once (and checked against the track's camera) for the whole session.
    images.take = std::make_shared<const VideoTake>(protocol);
    images.photo = images.take->Photo(images.take->first_posed());
  } else if (protocol.content.type != protocol::ContentType::kPicture || protocol.content.real_photos.empty()) {
    images.photo = ReadFieldImage(protocol, photo_field, photo_path, 1, 10, kMaxPhotoSidePx);
    // The photo not shown is still a photo of the scene: check it decodes too.
    if (!protocol.scene.board_free.empty() && !board_free)
      ReadFieldImage(protocol, "/scene/board_free", protocol.scene.board_free, 1, 10, kMaxPhotoSidePx);
    if (board_free) ReadFieldImage(protocol, "/scene/background", protocol.scene.background, 1, 10, kMaxPhotoSidePx);
  }
  if (protocol.content.type == protocol::ContentType::kPicture) {
    images.picture = ReadFieldImage(protocol, "/content/image",
                                    protocol.content.image.empty() ? scene::ResolveStimulus("face")
                                                                   : protocol.content.image,
                                    -1, 10, kMaxPhotoSidePx);
    return images;
  }
  if (!scene)
    throw InputError(At(protocol, "/scene/calib"), "a " + protocol::ToString(protocol.content.type) + " needs a calibration");
  // The objects are drawn in the calibrated camera's view of this photo.
  try {
    scene->RequireSameSize(images.photo, photo_path.string());
  } catch (const std::exception& e) {
    throw InputError(At(protocol, photo_field), std::string(e.what()) + " (the calibration " +
                                                    protocol.scene.calib.string() + " is of another photo)");
  }
  const std::string& name = protocol.content.texture;
  const bool shipped = name == "grid" || name == "soccer" || name == "wood";
  std::filesystem::path texture;
  try {
    texture = scene::ResolveStimulus(name);
  } catch (const std::exception& e) {
    throw InputError(At(protocol, shipped ? "/content/type" : "/content/texture"), e.what());
  }
  images.texture = ReadFieldImage(protocol, shipped ? "/content/type" : "/content/texture", texture, -1, 64,
                                  kMaxTextureSidePx);
  // A grid card of another count of cells than the shipped 5 x 5 is drawn here, at the shipped card's resolution.
  if (name == "grid" && protocol.content.cells != 5)
    images.texture = scene::GridBoard(images.texture.cols, protocol.content.cells);
  // An image on a card of a given size: its pixels keep their shape, or the card says another.
  if (protocol.content.type == protocol::ContentType::kGrid && !shipped) {
    const protocol::Content& c = protocol.content;
    const double w = c.size_mm > 0 ? c.size_mm : 2 * scene->board.square_mm, h = c.card_height_mm > 0 ? c.card_height_mm : w;
    const double image = double(images.texture.rows) / images.texture.cols;
    if (std::abs(h / w - image) > 0.02 * image)
    {
      auto mm = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        return std::string(text);
      };
      throw InputError(At(protocol, "/content/size_mm"),
                       "a card of " + mm(w) + " x " + mm(h) + " mm would stretch the " +
                           std::to_string(images.texture.cols) + " x " + std::to_string(images.texture.rows) +
                           " px texture; give \"size_mm\": [width, height] in its proportions (height = " +
                           mm(std::round(w * image * 10) / 10) + " mm at this width)");
    }
  }
  return images;
}

void CheckRealPhotos(const protocol::Protocol& protocol, const std::vector<TrialScene>& scenes,
                     std::set<double>* checked) {
  if (protocol.content.real_photos.empty()) return;
  for (const TrialScene& scene : scenes)
    if (scene.content == protocol::ContentType::kPicture && checked->insert(scene.distance_m).second) {
      const cv::Mat photo = ReadFieldImage(protocol, "/content/real_photos",
                                           protocol::RealPhotoFor(protocol.content, scene.distance_m), 1, 10,
                                           kMaxPhotoSidePx);
      // The real blur is worked out on the camera's whole image: a photo of another shape is not that image.
      if (const auto& camera = protocol.content.real_camera;
          camera && std::abs(double(photo.cols) / photo.rows -
                             double(camera->image_width_px) / camera->image_height_px) >
                        0.01 * camera->image_width_px / camera->image_height_px)
      {
        char sizes[160];
        std::snprintf(sizes, sizeof sizes, "its image is %dx%d px, but the real photo is %dx%d", camera->image_width_px,
                      camera->image_height_px, photo.cols, photo.rows);
        throw InputError(At(protocol, "/content/real_camera/camera"),
                         std::string(sizes) + " (another shape: not a whole photo of that camera): " +
                             protocol::RealPhotoFor(protocol.content, scene.distance_m).string());
      }
    }
}

}  // namespace blurcue::stimulus
