#pragma once
// Everything a session decides and checks before its first trial, without GL: the protocol, the trial list, the
// calibration, the images and every trial's scene. `blurcue run` starts from it and `blurcue validate` runs it in
// full, so a protocol that validates is one that runs, and every problem is reported the same way by both.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calib/scene_blur.h"
#include "display/profile.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "stimulus/stimulus.h"

namespace blurcue::procedure {

struct PreparedSession {
  protocol::Protocol protocol;
  std::string protocol_text;              // the file as read and parsed, with its conditions tables: RecordedText
  uint64_t seed = 0;                      // as given, else protocol::DefaultSeed(study, participant)
  std::string group;                      // the between-subject group whose blocks the trials hold ("": none)
  std::vector<protocol::Trial> trials;
  std::optional<calib::SceneCalib> scene;
  stimulus::StimulusImages images;
  std::vector<stimulus::TrialScene> scenes;         // one per trial
  display::Profile display;               // --display, else the protocol's display.profile, else the default
  stimulus::Presentation presentation;              // how a frame maps to the screen and the eye
  std::set<double> real_photos_checked;   // the distances whose real photo has been decoded (stimulus::CheckRealPhotos)
};

// Reads and validates the protocol, builds the participant's trial list, loads the calibration and every image
// the trials show (each must decode, at a size its use can show), and works out every trial's scene and radii.
// Throws Error(kInput) whose lines each name the protocol file and the JSON pointer of the field at fault.
// `display_profile` (--display) overrides the protocol's display.profile. `group`: the group to run (a resumed
// session's, or one assigned from the record); empty: assigned as if the record were empty (by_number, or the
// first group when balanced).
PreparedSession PrepareSession(const std::filesystem::path& protocol_file, const std::string& participant,
                               std::optional<uint64_t> seed, const std::filesystem::path& display_profile = {},
                               const std::string& group = "");

// The trials whose fitted blur falls where calibrate found the lens model not determined within 5 %
// (calib::UndeterminedNote at each side's depth, a ball's averaged over its run), and those whose card draws the
// measured blur of an edge with no usable section (calib::PooledNote): "N of M trials ..." with the calibration's
// note; "" where none does (or the session has no calibrated scene). validate and run print it.
std::string UndeterminedBlurNote(const PreparedSession& prepared);

// The session's blur plans (stimulus::PlanOnScreen: one radius, or per pixel by depth): the fixed trials' as planned;
// a procedure's trials' (their level moves as the participant answers, and run plans each at its level) at the
// procedure's least and largest level (a staircase's min and max, QUEST+'s stimuli). validate prints it.
struct BlurPlans {
  size_t fixed = 0, fixed_per_pixel = 0;
  size_t leveled = 0, per_pixel_at_least = 0, per_pixel_at_most = 0;
};
BlurPlans CountBlurPlans(const PreparedSession& prepared);

// PlanOnScreen for a trial of this session whose radii a procedure's level changed (ApplyLevel): on the photo, or on
// every frame of the take the trial shows (stimulus::PlanVideoOnScreen). Needs a scene (prepared.scene).
void PlanLeveled(const PreparedSession& prepared, const protocol::Trial& trial, stimulus::TrialScene* scene);

// Scenes already worked out, by what a trial shows (SceneKey) and a procedure's level: the participants of one study
// repeat the same trials in other orders, so `blurcue plan` describes and plans each once. One per thread.
struct SceneCache {
  std::map<std::string, stimulus::TrialScene> planned;                    // DescribeTrial + PlanOnScreen, by SceneKey
  std::map<std::pair<std::string, double>, stimulus::TrialScene> leveled;  // a procedure trial at a level (SessionLogic::SceneOf)
};

// Every field of a trial that its scene depends on (all but its index and repetition, which DescribeTrial reads only
// for its error messages), as one string.
std::string SceneKey(const protocol::Trial& trial);

// PrepareSession in two parts, for many participants of one study (blurcue plan): what every participant shares
// (the protocol, the calibration, the images, the display and the presentation; no trials yet), then one
// participant's seed, group, trials and scenes into it (replacing any before). Throw as PrepareSession.
PreparedSession PrepareStudy(const std::filesystem::path& protocol_file,
                             const std::filesystem::path& display_profile = {});
// How PrepareStudy parses `json` (the protocol read from `protocol_file`): against the board of the calibration its
// photo scene names (scene.calib, resolved as the parser does), read ahead so that an edge or section past that board
// is named with every other problem of the protocol; without that board (none, a take, one that does not load - which
// LoadProtocolScene then refuses), against the largest board a calibration can have. Each photo, picture, texture
// file and calibration it names is read as the session reads it (check_content: the image's header and whole bytes,
// the calibration parsed), so a cut photo is named with the protocol's other problems too.
protocol::ValidateOptions PreflightOptions(const Json& json, const std::filesystem::path& protocol_file);
// `cache`: scenes of earlier participants of the same study (PrepareStudy's, unchanged since) to reuse.
void PrepareParticipant(PreparedSession* study, const std::string& participant, std::optional<uint64_t> seed,
                        const std::string& group = "", SceneCache* cache = nullptr);

}  // namespace blurcue::procedure
