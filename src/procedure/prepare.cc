#include "procedure/prepare.h"

#include "stimulus/video_take.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/error.h"
#include "core/image.h"
#include "core/json_io.h"
#include "procedure/recorded_names.h"

namespace blurcue::procedure {

using stimulus::CheckRealPhotos;
using stimulus::DescribeTrial;
using stimulus::LoadProtocolScene;
using stimulus::LoadStimulusImages;
using stimulus::PlanOnScreen;
using stimulus::Presentation;
using stimulus::TrialScene;
using stimulus::CheckVideoTrial;

namespace {

// What reading `path` as the session reads it finds wrong (empty: nothing): an image's header and whole bytes, or a
// calibration parsed.
std::string ContentProblem(const std::filesystem::path& path, protocol::FileUse use) {
  try {
    if (use == protocol::FileUse::kImage)
      RequireImageFileWhole(path);
    else
      calib::LoadSceneCalib(path);
  } catch (const std::exception& e) {
    return use == protocol::FileUse::kImage ? std::string(e.what()) : std::string(stimulus::kNotACalibration) + e.what();
  }
  return "";
}

}  // namespace

protocol::ValidateOptions PreflightOptions(const Json& json, const std::filesystem::path& protocol_file) {
  protocol::ValidateOptions options;
  // Each photo, picture and calibration the protocol names read as the session reads it, so that a cut photo is named
  // with every other problem, not only once the rest is mended.
  options.check_content = ContentProblem;
  if (!json.is_object() || !json.contains("scene") || !json["scene"].is_object()) return options;
  const Json& scene = json["scene"];
  if (scene.contains("track") || !scene.contains("calib") || !scene["calib"].is_string()) return options;
  const std::filesystem::path base = protocol_file.has_parent_path() ? protocol_file.parent_path() : ".";
  const std::filesystem::path path = (base / scene["calib"].get<std::string>()).lexically_normal();
  // Only a regular file, as the parser checks it after: a FIFO or a device would be waited on here.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return options;
  // Read once: its board for the parser, and what it found wrong as the calibration's content problem.
  std::string wrong;
  try {
    const calib::SceneCalib calib = calib::LoadSceneCalib(path);
    options.board_cols = calib.board.cols, options.board_rows = calib.board.rows;
  } catch (const std::exception& e) {
    wrong = std::string(stimulus::kNotACalibration) + e.what();
  }
  options.check_content = [path, wrong](const std::filesystem::path& file, protocol::FileUse use) {
    return use == protocol::FileUse::kCalibration && file == path ? wrong : ContentProblem(file, use);
  };
  return options;
}

PreparedSession PrepareStudy(const std::filesystem::path& protocol_file, const std::filesystem::path& display_profile) {
  PreparedSession s;
  // Read once: the text recorded with the session is the text that was validated.
  const std::string text = ReadTextFile(protocol_file);
  const Json json = ParseJson(text, protocol_file.string());
  s.protocol = protocol::ParseProtocol(json, protocol_file, PreflightOptions(json, protocol_file));
  // Each design variable in a column of its own (the record's rule: recorded_names.h), before anything else is read.
  CheckRecordedNames(s.protocol);
  s.protocol_text = protocol::RecordedText(text, s.protocol);
  s.scene = LoadProtocolScene(s.protocol);
  s.images = LoadStimulusImages(s.protocol, s.scene);
  if (s.images.take) {  // the take the trials are drawn on, in the recorded text (stimulus::TakeIdentity)
    Json recorded = ParseJson(s.protocol_text, protocol_file.string());
    recorded["recorded_take"] = stimulus::TakeIdentity(*s.images.take);
    s.protocol_text = recorded.dump(2, ' ', false, Json::error_handler_t::replace);
  }
  // A ball on a tracked video without content.exposure_ms is streaked as the camera streaked the take: its
  // camera's exposure_ms, or half a frame of the take where the camera does not state it (as `blurcue ar`).
  if (s.images.take && s.protocol.content.type == protocol::ContentType::kBall && !s.protocol.content.exposure_given) {
    const std::optional<double> camera = s.images.take->take().camera().exposure_ms;
    const double fps = s.images.take->fps();
    if (const std::string beyond = stimulus::ExposureBeyondFrame(camera.value_or(0), fps); !beyond.empty())
      throw InputError(protocol_file.string() + ": /scene/track",
                       "the take's camera says exposure_ms " + Num(*camera) + ", " + beyond +
                           ": not this take's camera? give content.exposure_ms");
    s.protocol.content.exposure_ms = camera ? *camera : 1000 / fps / 2;
  }
  if (!display_profile.empty()) {
    s.display = display::LoadProfile(display_profile);
  } else if (!s.protocol.display.profile.empty()) {
    try {
      s.display = display::LoadProfile(s.protocol.display.profile);
    } catch (const Error& e) {
      throw e.Wrapped(ErrorKind::kInput, protocol_file.string() + ": /display/profile: ");
    }
  }
  s.presentation = Presentation::Of(s.protocol, s.images, s.display);
  // A take's frames are held decoded and, for the screen, resampled: both must fit.
  if (s.images.take) s.images.take->CheckMemory(s.protocol, {s.presentation.view.photo_width_px,
                                                             s.presentation.view.photo_height_px});
  return s;
}

namespace {

// A trial's scene with its blur plan on the session's screen (one radius, or per pixel by depth where the object's
// depth asks); on video, as the take plays (its radii averaged over the frames shown) and checked in every frame of
// the take it can show.
TrialScene Describe(const PreparedSession& s, const protocol::Trial& trial) {
  if (s.images.take) {
    TrialScene scene = stimulus::DescribeVideoTrial(s.protocol, *s.images.take, trial, s.presentation);
    CheckVideoTrial(s.protocol, *s.images.take, trial, scene);
    return scene;
  }
  TrialScene scene = DescribeTrial(s.protocol, trial, s.scene ? &*s.scene : nullptr, &s.presentation);
  if (!s.scene) return scene;
  PlanOnScreen(s.protocol, *s.scene, s.presentation, &scene);
  // Drawable on this screen: as the trial starts, and for a procedure's trial at the largest level it can reach (a
  // staircase's max, QUEST+'s largest stimulus), so that run never stops at a radius past the renderer's.
  stimulus::CheckBlurOnScreen(s.protocol, trial, *s.scene, s.presentation, scene);
  if (trial.cell >= 0) {
    const protocol::Block& block = *protocol::BlockOf(s.protocol, trial);
    const protocol::Procedure& p = *block.procedure;
    const bool staircase = p.kind == protocol::Procedure::Kind::kStaircase;
    const double most = staircase || p.stimuli.empty() ? p.max : *std::max_element(p.stimuli.begin(), p.stimuli.end());
    TrialScene at_most = scene;
    stimulus::ApplyLevel(p, trial, most, s.presentation, &at_most);
    stimulus::CheckBlurOnScreen(s.protocol, trial, *s.scene, s.presentation, at_most,
                                block.pointer + (staircase ? "/procedure/max" : "/procedure/stimuli"),
                                "its largest level, " + Num(most));
  }
  return scene;
}

}  // namespace

void PlanLeveled(const PreparedSession& s, const protocol::Trial& trial, TrialScene* scene) {
  if (s.images.take)
    stimulus::PlanVideoOnScreen(s.protocol, *s.images.take, trial, s.presentation, scene);
  else
    PlanOnScreen(s.protocol, *s.scene, s.presentation, scene);
}

BlurPlans CountBlurPlans(const PreparedSession& s) {
  BlurPlans plans;
  std::map<std::pair<std::string, double>, bool> planned;  // participants' trials repeat: each planned once
  for (size_t i = 0; i < s.trials.size() && i < s.scenes.size(); ++i) {
    const protocol::Trial& trial = s.trials[i];
    if (trial.cell < 0) {
      ++plans.fixed, plans.fixed_per_pixel += s.scenes[i].per_pixel;
      continue;
    }
    ++plans.leveled;
    if (!s.scene && !s.images.take) continue;
    const protocol::Procedure& p = *protocol::BlockOf(s.protocol, trial)->procedure;
    const bool staircase = p.kind == protocol::Procedure::Kind::kStaircase;
    const double least = staircase || p.stimuli.empty() ? p.min : *std::min_element(p.stimuli.begin(), p.stimuli.end());
    const double most = staircase || p.stimuli.empty() ? p.max : *std::max_element(p.stimuli.begin(), p.stimuli.end());
    auto per_pixel = [&](double level) {
      const auto key = std::make_pair(SceneKey(trial), level);
      if (const auto it = planned.find(key); it != planned.end()) return it->second;
      TrialScene scene = s.scenes[i];
      stimulus::ApplyLevel(p, trial, level, s.presentation, &scene);
      PlanLeveled(s, trial, &scene);
      return planned[key] = scene.per_pixel;
    };
    plans.per_pixel_at_least += per_pixel(least), plans.per_pixel_at_most += per_pixel(most);
  }
  return plans;
}

std::string SceneKey(const protocol::Trial& t) {
  std::string key = t.block + '\n' + std::to_string(int(t.task)) + ' ' + std::to_string(t.practice) + ' ' +
                    std::to_string(t.round) + ' ' + std::to_string(t.swapped) + ' ' + std::to_string(t.cell) + ' ' +
                    t.test_side + ' ' + std::to_string(t.start_index) + '\n' +
                    protocol::ToJson(t.levels).dump() + '\n' + protocol::ToJson(t.left).dump() + '\n' +
                    protocol::ToJson(t.right).dump() + '\n';
  for (double level : t.adjust_levels) key += std::to_string(level) + ' ';
  return key;
}

void PrepareParticipant(PreparedSession* s, const std::string& participant, std::optional<uint64_t> seed,
                        const std::string& group, SceneCache* cache) {
  const std::string file = s->protocol.file.string();
  s->seed = seed ? *seed : protocol::DefaultSeed(s->protocol.name, participant);
  s->group = !group.empty() ? group : protocol::AssignGroup(s->protocol, participant, {});
  if (s->protocol.groups && std::find(s->protocol.groups->names.begin(), s->protocol.groups->names.end(), s->group) ==
                                s->protocol.groups->names.end())
    throw InputError(file + ": /groups/names", "has no group \"" + s->group + "\"");
  s->trials = protocol::BuildTrials(s->protocol, participant, s->seed, s->group);
  // Every trial's radii before anything is shown or saved: a source that cannot be evaluated stops here, not in
  // front of a participant.
  s->scenes.clear();
  s->scenes.reserve(s->trials.size());
  if (cache) {
    // A scene is a function of the trial's content, the protocol, calibration and presentation: a trial seen before
    // (it checked then) is the scene made then.
    for (const protocol::Trial& trial : s->trials) {
      const std::string key = SceneKey(trial);
      auto it = cache->planned.find(key);
      if (it == cache->planned.end()) {
        TrialScene scene = Describe(*s, trial);
        CheckRealPhotos(s->protocol, {scene}, &s->real_photos_checked);
        it = cache->planned.emplace(key, std::move(scene)).first;
      }
      s->scenes.push_back(it->second);
    }
    return;
  }
  for (const protocol::Trial& trial : s->trials) s->scenes.push_back(Describe(*s, trial));
  CheckRealPhotos(s->protocol, s->scenes, &s->real_photos_checked);
}

PreparedSession PrepareSession(const std::filesystem::path& protocol_file, const std::string& participant,
                               std::optional<uint64_t> seed, const std::filesystem::path& display_profile,
                               const std::string& group) {
  PreparedSession s = PrepareStudy(protocol_file, display_profile);
  PrepareParticipant(&s, participant, seed, group);
  return s;
}

std::string UndeterminedBlurNote(const PreparedSession& prepared) {
  if (!prepared.scene) return "";
  size_t n_fitted = 0, n_pooled = 0;
  std::string fitted, pooled;
  for (const TrialScene& scene : prepared.scenes) {
    std::string first_fitted, first_pooled;
    for (const stimulus::SideShown& side : scene.sides) {
      if (first_fitted.empty()) first_fitted = calib::UndeterminedNote(*prepared.scene, side.source, side.u_mm);
      // A card at an edge draws that edge's measured value (a ball's run crosses several: not said).
      if (first_pooled.empty() && scene.content == protocol::ContentType::kGrid && scene.edge > 0)
        first_pooled = calib::PooledNote(*prepared.scene, side.source, scene.edge);
    }
    if (!first_fitted.empty()) n_fitted += 1, fitted = fitted.empty() ? first_fitted : fitted;
    if (!first_pooled.empty()) n_pooled += 1, pooled = pooled.empty() ? first_pooled : pooled;
  }
  const std::string of = " of " + std::to_string(prepared.scenes.size()) + " trials show the ";
  std::string note;
  if (n_fitted > 0)
    note = std::to_string(n_fitted) + of + "fitted blur where it is not determined within 5 %; the first: " + fitted;
  if (n_pooled > 0)
    note += (note.empty() ? "" : "; and ") + std::to_string(n_pooled) + of +
            "measured blur of an edge with no usable section; the first: " + pooled;
  return note;
}

}  // namespace blurcue::procedure
