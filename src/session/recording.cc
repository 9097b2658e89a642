#include "session/recording.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <utility>

#include "core/hash.h"
#include "core/error.h"
#include "display/profile.h"
#include "protocol/design.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "store/columns.h"
#include "store/export.h"
#include "store/record.h"

namespace blurcue::session {

using stimulus::Presentation;
using stimulus::TrialScene;

namespace {

// A procedure's level as the protocol writes its numbers. A staircase steps by adding (0.5 - 0.1 - 0.1 - 0.1 is
// 0.20000000000000004 in binary), so the level it reached is recorded at 12 significant digits: the decimal its start
// and steps give (0.2), within 1e-12 of the level shown (a resumed session's replay allows 1e-9).
double LevelAsGiven(double level) {
  if (!std::isfinite(level)) return level;
  char text[32];
  std::snprintf(text, sizeof text, "%.12g", level);
  return std::strtod(text, nullptr);
}

// The trial list as saved: one record per trial, with its planned radii.
std::vector<store::TrialRecord> TrialRecords(const procedure::PreparedSession& s) {
  const protocol::Protocol& protocol = s.protocol;
  std::vector<store::TrialRecord> records;
  for (const protocol::Trial& trial : s.trials) {
    store::TrialRecord r;
    r.index = trial.index;
    r.block = protocol::BlockIndex(protocol, trial);
    const TrialScene& planned = s.scenes[size_t(trial.index)];
    r.factors_json = TrialVariables(trial, planned, s.presentation).dump();
    r.source_json = {protocol::ToJson(trial.left).dump(), protocol::ToJson(trial.right).dump()};
    r.block_name = trial.block;
    r.task = protocol::ToString(trial.task);
    r.practice = trial.practice;
    r.swapped = trial.swapped;
    r.cell = protocol::CellLevels(protocol, trial);
    if (planned.content != protocol::ContentType::kPicture &&
        protocol::TraitsOf(trial.task).shows != protocol::TaskShows::kPicture) {
      for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values)
        if (side == protocol::Side::kLeft || !planned.left_only)
          r.r_px[protocol::Index(side)] = planned.side(side).r_px;
      r.r_scene_px = planned.r_scene_px;
    }
    records.push_back(std::move(r));
  }
  return records;
}

// protocol::DescribeDesign as the record keeps it: a level named store::DesignColumn(name) (factor_NAME for one named
// like a column of trials.csv, as TrialVariables records it).
std::vector<store::DesignColumnRecord> DesignRecord(const std::vector<protocol::DesignColumn>& design) {
  std::vector<store::DesignColumnRecord> out;
  for (const protocol::DesignColumn& c : design) {
    store::DesignColumnRecord r;
    r.name = c.level ? store::DesignColumn(c.name) : c.name;
    r.role = protocol::ToString(c.role);
    r.type = protocol::ToString(c.type);
    r.unit = c.unit;
    r.numbers = c.numbers;
    r.names = c.names;
    r.min = c.min;
    r.max = c.max;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace

std::string RecordedColumn(const std::string& name) { return store::DesignColumn(name); }
bool IsRecordColumn(const std::string& column) { return store::IsRecordedName(column); }

uint64_t DefaultSessionSeed(const std::string& study, const std::string& participant, int64_t session_number) {
  if (session_number <= 1) return protocol::DefaultSeed(study, participant);
  return Fnv1a64(study + "/" + participant + "#" + std::to_string(session_number));
}

Recording::Recording(std::unique_ptr<store::Record> record) : record_(std::move(record)) {}
Recording::~Recording() = default;
Recording::Recording(Recording&&) noexcept = default;

Recording Recording::Open(const std::filesystem::path& db) {
  return Recording(std::make_unique<store::Record>(store::Record::Open(db)));
}

std::vector<int64_t> Recording::CompletedSessions(const std::string& study, const std::string& participant) {
  return record_->CompletedSessions(study, participant);
}

std::vector<std::string> Recording::CodesDifferingInCase(const std::string& study, const std::string& participant) {
  return record_->CodesDifferingInCase(study, participant);
}

SessionStart Recording::StartOrResumeSession(const std::string& study, const std::string& participant,
                                             const std::string& protocol_text, uint64_t seed,
                                             const SessionInfo& info, bool resume) {
  store::SessionMeta meta;
  meta.display = info.display;
  meta.display_profile = info.display_profile;
  meta.group = info.group;
  meta.assign_group = info.assign_group;
  meta.participant_info = info.participant_info;
  meta.simulated = info.simulated;
  meta.observer_params = info.observer_params;
  meta.canonical_observer = [](const std::string& stored) {
    try {
      return procedure::ToString(procedure::ParseObserver(stored));
    } catch (const Error&) {
      return stored;  // not a spec this build reads: compared as stored, and the message shows it
    }
  };
  meta.window = info.window;
  meta.protocol_version = info.protocol_version;
  meta.design = DesignRecord(info.design);
  meta.procedures = store::ProcedureRecords(info.blocks);
  meta.seed_given = info.seed_given;
  meta.seed_for_number = info.seed_for_number;
  return record_->StartOrResumeSession(study, participant, protocol_text, seed, meta, resume);
}

void Recording::SaveTrialList(int64_t session, const procedure::PreparedSession& prepared) {
  record_->SaveTrialList(session, TrialRecords(prepared));
}

void Recording::CheckTrialList(int64_t session, const procedure::PreparedSession& prepared) {
  record_->CheckTrialList(session, TrialRecords(prepared));
}

void Recording::RecordResponse(int64_t session, int64_t trial_index, const Response& response,
                               const std::vector<FrameRecord>& frames) {
  store::Response r;
  r.choice = procedure::Name(response.choice);
  r.rt_ms = response.rt_ms;
  r.adjustment_json = response.adjustment_json;
  r.shown_json = response.shown_json;
  if (response.level) r.level = LevelAsGiven(*response.level);
  r.r_px = response.r_px;
  r.correct = response.correct;
  record_->RecordResponse(session, trial_index, r, frames);
}

void Recording::Heartbeat(int64_t session) { record_->Heartbeat(session); }

void Recording::CompleteSession(int64_t session) { record_->FinishSession(session, store::SessionStatus::kCompleted); }

int64_t Recording::FirstUnansweredTrial(int64_t session) { return record_->FirstUnansweredTrial(session); }
int64_t Recording::DroppedFrames(int64_t session) { return record_->DroppedFrames(session); }

std::map<int64_t, RecordedAnswer> Recording::AnsweredTrials(int64_t session) {
  return record_->AnsweredTrials(session);
}

namespace {

// The variables of TrialVariables, typed (store::RecordedVariables names them).
store::RecordedVariables Variables(const protocol::Trial& trial, const TrialScene& scene,
                                   const Presentation& presentation) {
  store::RecordedVariables v;
  v.practice = trial.practice;
  v.block_name = trial.block;
  v.swapped = trial.swapped;
  if (trial.round >= 0) v.round = trial.round + 1;  // a practice block run until a criterion: which run
  if (trial.cell >= 0) {  // a procedure's trial: which of its block's procedures, the test side, the level shown
    v.procedure_cell = trial.cell;
    v.test_side = trial.test_side;
    if (!std::isnan(scene.level)) v.level = LevelAsGiven(scene.level);
  }
  // Odd one out: the interval that showed the right side's object (the correct answer), and how many there were.
  const protocol::TaskTraits& task = protocol::TraitsOf(trial.task);
  if (scene.intervals > 2 && task.answer == protocol::TaskAnswer::kSide) {
    v.odd_interval = protocol::TestInterval(trial);
    v.intervals = scene.intervals;
  }
  // Rounded to 1e-4 px: the record is read by people and charts, not fed back.
  auto round4 = [](double x) { return std::round(x * 1e4) / 1e4; };
  if (task.answer == protocol::TaskAnswer::kLevel) {
    if (trial.start_index >= 0 && size_t(trial.start_index) < trial.adjust_levels.size())
      v.start_level = trial.adjust_levels[size_t(trial.start_index)];
    // The levels in the order "next" steps through them (cyclic): what the participant could reach, as shown.
    std::string levels;
    for (double level : trial.adjust_levels) levels += (levels.empty() ? "" : ";") + protocol::LevelText(level);
    v.adjust_levels = levels;
  }
  constexpr size_t kScene = store::RecordedVariables::kScene;  // the scene's place after the two sides
  if (scene.content == protocol::ContentType::kPicture) {
    // The virtual picture's width as shown (a level c's blur is r = 2 x 0.1874 x this / c arcmin), and the real
    // picture's blur when its camera is known: in its camera's px, on the screen and on the eye.
    v.picture_width_arcmin = round4(presentation.Arcmin(presentation.layout.picture.width));
    if (presentation.real_frame_px_per_px > 0) {
      v.r_px[kScene] = round4(scene.r_scene_px);
      v.r_screen_px[kScene] = round4(presentation.ScreenPx(scene.r_scene_px * presentation.real_frame_px_per_px));
      v.r_arcmin[kScene] = round4(presentation.RealArcmin(scene.r_scene_px));
    }
  } else if (task.shows != protocol::TaskShows::kPicture) {
    // Each radius as the camera made it (photo px), as the window shows it (screen px) and as the eye gets it.
    // The single layout shows only its object, recorded as the left side.
    auto radius = [&](size_t place, double r) {
      v.r_px[place] = round4(r);
      v.r_screen_px[place] = round4(presentation.ScreenPx(r));
      v.r_arcmin[place] = round4(presentation.Arcmin(r));
    };
    for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values)
      if (side == protocol::Side::kLeft || !scene.left_only) radius(protocol::Index(side), scene.side(side).r_px);
    radius(kScene, scene.r_scene_px);
    v.screen_px_per_photo_px = std::round(presentation.scale * 1e6) / 1e6;
    v.kernel = protocol::ToString(scene.kernel);
    v.blur_plan = scene.per_pixel ? "per_pixel" : "one_radius";
    v.r_span_screen_px = round4(scene.r_span_screen_px);
    v.exposure_ms = scene.exposure_ms;
    for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values) {
      if (scene.left_only && side == protocol::Side::kRight) continue;
      const stimulus::SideShown& shown = scene.side(side);
      store::SideVariables& out = v.sides[protocol::Index(side)];
      // As drawn (render::Psf): a floor beyond half the radius is the whole of it.
      const double floor = std::min(shown.floor_sigma_px, std::max(0.0, shown.r_px) / 2);
      out.floor_sigma_px = round4(floor);
      out.floor_sigma_screen_px = round4(presentation.ScreenPx(floor));
      out.motion_x_screen_px = round4(presentation.ScreenPx(shown.motion_px[0]));
      out.motion_y_screen_px = round4(presentation.ScreenPx(shown.motion_px[1]));
      // Where it is: its depth (0.01 mm) and its centre's elevation on the display from the principal point.
      out.u_mm = std::round(shown.u_mm * 100) / 100;
      const double below_mm = presentation.ScreenPx(shown.below_axis_px) * display::MmPerPx(presentation.profile);
      out.elevation_deg = round4(-std::atan(below_mm / presentation.profile.distance_mm) * 180 / M_PI);
      out.size_deg = round4(shown.size_deg);
    }
    v.brightness = scene.brightness;
    v.contrast = scene.contrast;
    v.white_balance_r = scene.white_balance[0];
    v.white_balance_g = scene.white_balance[1];
    v.white_balance_b = scene.white_balance[2];
  }
  return v;
}

}  // namespace

Json TrialVariables(const protocol::Trial& trial, const TrialScene& scene, const Presentation& presentation) {
  // Every level under store::DesignColumn's name: one named like a column of trials.csv or a variable recorded
  // below (status, r_left_px, level, correct, ...) as factor_NAME, so what is recorded never overwrites a level.
  // A level object's values get columns of their own (a pattern's speed_cm_s, a conditions table's edge); the sides
  // are recorded as such. A conditions table's row object itself is no factor of the design: only its columns stay.
  Json v = store::LevelVariables(protocol::ToJson(trial.levels));
  v.update(store::VariablesJson(Variables(trial, scene, presentation)));
  return v;
}

std::string ShownVariables(const protocol::Trial& trial, const TrialScene& scene, const Presentation& presentation,
                           const procedure::Scored& scored) {
  store::RecordedVariables v = Variables(trial, scene, presentation);
  v.correct = scored.correct.value_or(false);
  if (scored.reversals_before) v.reversals = *scored.reversals_before;
  if (scored.posterior) {
    v.posterior_threshold = scored.posterior->first;
    v.posterior_slope = scored.posterior->second;
  }
  Json shown = store::LevelVariables(protocol::ToJson(trial.levels));
  shown.update(store::VariablesJson(v));
  return shown.dump();
}

std::string SkippedVariables(const procedure::Skip& skip) {
  store::RecordedVariables v;
  v.skipped = skip.why;
  if (skip.reversals) v.reversals = *skip.reversals;
  return store::VariablesJson(v).dump();
}

}  // namespace blurcue::session
