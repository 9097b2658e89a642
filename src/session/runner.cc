#include "session/runner.h"

#include "stimulus/video_take.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/json_io.h"
#include "core/names.h"
#include "core/typed.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "render/gl_context.h"
#include "procedure/answer.h"
#include "session/gl_presenters.h"
#include "session/keys.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "session/recording.h"
#include "session/responder.h"
#include "session/stimulus_renderer.h"
#include "session/trial_loop.h"

namespace blurcue::session {

namespace {

// trial-NNNN.png or trial-NNNN.json (four digits or more): what a capture writes.
bool IsCaptureFile(const std::string& name) {
  if (name.rfind("trial-", 0) != 0) return false;
  size_t i = 6;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
  const std::string ext = name.substr(i);
  return i >= 10 && (ext == ".png" || ext == ".json");
}

}  // namespace

void CheckCaptureFolder(const std::filesystem::path& dir, const std::string& study, const std::string& participant) {
  namespace fs = std::filesystem;
  const std::string where = dir.string();
  std::error_code ec;
  // A link is not followed: as root, --capture on a link to /etc used to write trial-0001.png into /etc.
  if (fs::is_symlink(fs::symlink_status(dir, ec)))
    throw InputError(where, "--capture: is a symbolic link; captures go only into a real folder (name the folder it "
                            "points to if that is meant)");
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError(where, "--capture: cannot make a folder here (" + (ec ? ec.message() : std::string("not a folder")) +
                                ")");
  // Empty, or an earlier capture of this participant in this study (a resumed session goes on where it left off):
  // anything else would be overwritten or mixed with this session's frames. A capture's images come with its
  // trial-NNNN.json: images alone are someone's own (they were overwritten).
  std::string first_image;
  int captures = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_symlink())
      throw InputError(where, "--capture: holds a symbolic link, " + Echo(name) + "; capture into an empty folder");
    if (!IsCaptureFile(name) || !entry.is_regular_file())
      throw InputError(where, "--capture: holds " + Echo(name) + ", which is not a capture; capture into an empty "
                              "folder (or one holding only this participant's earlier capture)");
    if (entry.path().extension() != ".json") {
      if (first_image.empty()) first_image = name;
      continue;
    }
    ++captures;
    std::string owner;
    try {
      const Json frame = ReadJsonFile(entry.path());
      if (frame.value("protocol", "") != study || frame.value("participant", "") != participant)
        owner = "participant " + frame.value("participant", std::string("?")) + " of study " +
                frame.value("protocol", std::string("?"));
    } catch (const std::exception&) {
      owner = "something else";
    }
    if (!owner.empty())
      throw InputError(where, "--capture: holds the capture of " + OneLine(owner) + " (" + name + "), which this "
                              "session would overwrite; capture into another folder");
  }
  if (ec) throw InputError(where, "--capture: cannot list the folder (" + ec.message() + ")");
  if (!first_image.empty() && captures == 0)
    throw InputError(where, "--capture: holds " + Echo(first_image) + " and no trial-NNNN.json: images, not a "
                            "capture (one's own?); capture into another folder");
  // Writable now, not at the first trial: a read-only folder used to stop the session there, left running at 0.
  const fs::path probe = dir / (".blurcue-capture-probe-" + std::to_string(getpid()));
  const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) throw InputError(where, std::string("--capture: cannot write here (") + std::strerror(errno) + ")");
  ::close(fd);
  fs::remove(probe, ec);
}

// The participant information a session records: --info values checked against the protocol's fields, the
// required ones that are missing asked for in the terminal (stdin a terminal) or refused; a resumed session's
// recorded information, which --info may repeat but not change.
Json CollectInfo(const protocol::Protocol& p, const RunOptions& options, const GroupsSoFar& so_far) {
  auto field_of = [&](const std::string& key) -> const protocol::InfoField* {
    for (const auto& f : p.participant_info)
      if (f.key == key) return &f;
    return nullptr;
  };
  auto value_of = [](const protocol::InfoField& f, const std::string& text) {
    // Checked by CheckInfoValue before: a decimal number in the field's range.
    switch (f.type) {
      case protocol::InfoType::kInteger: return Json(int64_t(*ParseDecimal(text)));
      case protocol::InfoType::kNumber: return Json(*ParseDecimal(text));
      case protocol::InfoType::kChoice:
      case protocol::InfoType::kText: break;
    }
    return Json(text);
  };
  auto describe = [](const protocol::InfoField& f) {
    switch (f.type) {
      case protocol::InfoType::kChoice: {
        std::string list;
        for (const auto& c : f.choices) list += (list.empty() ? "" : " / ") + c;
        return list;
      }
      case protocol::InfoType::kText: return std::string("text");
      case protocol::InfoType::kInteger:
      case protocol::InfoType::kNumber: break;
    }
    char range[64];
    std::snprintf(range, sizeof range, "%g-%g", f.min, f.max);
    return std::string(range);
  };
  std::string asked;
  std::vector<std::string> keys;
  for (const auto& f : p.participant_info) asked += (asked.empty() ? "" : ", ") + f.key, keys.push_back(f.key);
  Json info = Json::object();
  for (const auto& [key, text] : options.info) {
    const protocol::InfoField* f = field_of(key);
    if (!f)
      throw Error(ErrorKind::kUsage, "--info " + Echo(key, false) + ": " + options.protocol_file.string() +
                                         (asked.empty() ? " asks for no participant information"
                                                        : " asks for " + asked + " (participant_info), not " +
                                                              Echo(key, false) + DidYouMean(key, keys)));
    if (const std::string why = protocol::CheckInfoValue(*f, text); !why.empty())
      throw Error(ErrorKind::kUsage, "--info " + key + "=" + Echo(text, false) + ": " + why);
    info[key] = value_of(*f, text);
  }
  if (options.resume && so_far.unfinished) {
    const Json recorded = ParseJson(so_far.unfinished_info, options.db.string());
    for (const auto& [key, value] : info.items())
      if (!recorded.contains(key) || recorded[key] != value)
        throw InputError(options.db.string(), "--info " + key + ": the unfinished session recorded " +
                                                  (recorded.contains(key) ? recorded[key].dump() : "nothing") +
                                                  ", got " + value.dump() + "; a session keeps what it recorded");
    return recorded;
  }
  for (const auto& f : p.participant_info) {
    if (info.contains(f.key) || !f.required) continue;
    if (!options.ask)
      throw Error(ErrorKind::kUsage, "--info: " + options.protocol_file.string() + " asks for " + f.key + " (" +
                                         describe(f) + "); give --info " + f.key + "=VALUE");
    std::string problem;
    for (int tries = 0;; ++tries) {
      std::string line;
      if (!options.ask(problem + (f.prompt.empty() ? f.key : f.prompt) + " (" + describe(f) + "): ", &line) &&
          line.empty())
        throw Error(ErrorKind::kUsage, "--info: no answer for " + f.key);
      const std::string why = protocol::CheckInfoValue(f, line);
      if (why.empty()) {
        info[f.key] = value_of(f, line);
        break;
      }
      problem = "  " + f.key + " " + why + "\n";
      if (tries >= 4) throw Error(ErrorKind::kUsage, "--info " + f.key + ": " + why);
    }
  }
  return info;
}

// The participant's window (or an offscreen context for a simulated observer without one), of the protocol's display
// size: a window of another size (a window manager's choice, a full screen of another mode) would show every radius
// at another scale than the record states.
std::unique_ptr<render::GlContext> OpenDisplay(const RunOptions& options, const protocol::Protocol& protocol,
                                               bool window, bool simulated) {
  if (!window) return render::GlContext::CreateOffscreen();
  render::WindowOptions w;
  w.width_px = protocol.display.width_px;
  w.height_px = protocol.display.height_px;
  w.fullscreen = protocol.display.fullscreen;
  w.monitor = protocol.display.monitor;
  w.title = "blurcue - " + protocol.name;  // then Runner::Title names what is on screen
  std::unique_ptr<render::GlContext> context;
  try {
    context = render::GlContext::CreateWindow(w);
  } catch (const Error& e) {
    // Only run knows the way round a missing display: a simulated observer needs no window.
    if (e.kind() != ErrorKind::kUsage || simulated) throw;
    throw Error(ErrorKind::kUsage, std::string(e.what()) + "; to try the protocol without a participant, run it "
                                                            "with --observer sim");
  }
  if (context->width_px() != protocol.display.width_px || context->height_px() != protocol.display.height_px)
    throw InputError(options.protocol_file.string() + ": /display",
                     "the window opened at " + std::to_string(context->width_px()) + " x " +
                         std::to_string(context->height_px()) + " px, the protocol's display says " +
                         std::to_string(protocol.display.width_px) + " x " + std::to_string(protocol.display.height_px) +
                         " px; set width_px/height_px to the screen's (full screen: the monitor's mode)");
  return context;
}

// What the record keeps about a session besides its trials: the display as opened, the group and how a balanced one
// is decided, the participant's information, the observer, the design, and where its seed came from.
SessionInfo DescribeSession(const RunOptions& options, const procedure::PreparedSession& prepared,
                            const render::GlContext& context, bool window,
                            const std::optional<procedure::ObserverParams>& observer, const Json& info, bool balanced,
                            int64_t session_number) {
  const protocol::Protocol& protocol = prepared.protocol;
  SessionInfo meta;
  char display[256];
  std::snprintf(display, sizeof display, "%s %dx%d%s; %s%s", window ? "window" : "headless",
                window ? context.width_px() : protocol.display.width_px,
                window ? context.height_px() : protocol.display.height_px,
                window && context.RefreshHz() > 0 ? ("@" + std::to_string(int(context.RefreshHz()))).c_str() : "",
                context.Describe().c_str(), observer ? ("; observer " + procedure::ToString(*observer)).c_str() : "");
  meta.display = display;
  meta.display_profile = display::ToJson(prepared.display).dump();
  meta.group = prepared.group;
  if (balanced) {
    const std::string participant = options.participant;
    const protocol::Protocol* p = &protocol;
    meta.assign_group = [p, participant](const std::map<std::string, int64_t>& sessions) {
      return protocol::AssignGroup(*p, participant, sessions);
    };
  }
  meta.participant_info = info.dump();
  meta.simulated = observer.has_value();
  meta.observer_params = observer ? procedure::ToString(*observer) : "";
  meta.window = window;
  meta.protocol_version = protocol.version;
  meta.design = protocol::DescribeDesign(protocol);
  meta.blocks = protocol.blocks;
  meta.seed_given = options.seed.has_value();
  if (!options.seed && !options.resume) meta.seed_for_number = session_number;
  return meta;
}

RunResult RunSession(const RunOptions& options) {
  protocol::CheckParticipantId(options.participant);
  std::optional<procedure::ObserverParams> observer;
  if (!options.observer.empty()) observer = procedure::ParseObserver(options.observer);
  if (options.sim_fps < 0) throw Error(ErrorKind::kUsage, "--sim-fps must be > 0");

  // --resume continues what a record holds: a missing record holds nothing (and is not created).
  if (options.resume && !std::filesystem::exists(options.db))
    throw InputError(options.db.string(), "--resume: no such record, so there is no session to continue; leave out "
                                          "--resume to start one");
  // Groups and participant information: what the record already says (a resumed session keeps its group and its
  // information), then the group a new session gets and the information it is given.
  const Json head_json = ReadJsonFile(options.protocol_file);
  const protocol::Protocol head = protocol::ParseProtocol(
      head_json, options.protocol_file, procedure::PreflightOptions(head_json, options.protocol_file));
  GroupsSoFar so_far;
  if (head.groups || !head.participant_info.empty())
    so_far = PeekGroups(options.db, head.name, options.participant);
  // A participant's session run again (--again) stays in the group of their earlier one: a between-subject
  // participant shown both groups' conditions would belong to neither (it used to be assigned afresh).
  const bool stays = head.groups && !so_far.earlier_group.empty() &&
                     std::count(head.groups->names.begin(), head.groups->names.end(), so_far.earlier_group) > 0;
  const std::string group = !head.groups       ? ""
                            : so_far.unfinished ? so_far.unfinished_group
                            : stays             ? so_far.earlier_group
                                                : protocol::AssignGroup(head, options.participant, so_far.sessions);
  const Json info = CollectInfo(head, options, so_far);
  // A new session's number decides its default seed (the record decides the number again when it starts the
  // session); a resumed one runs with the seed it recorded.
  const SessionsSoFar sessions = PeekSessions(options.db, head.name, options.participant);
  const int64_t session_number = options.resume && sessions.unfinished ? sessions.unfinished_number : sessions.next_number;
  const uint64_t session_seed = options.seed                            ? *options.seed
                                : options.resume && sessions.unfinished ? sessions.unfinished_seed
                                : DefaultSessionSeed(head.name, options.participant, session_number);
  // Everything checked before the first trial is what `blurcue validate` checks: the same function.
  const procedure::PreparedSession prepared =
      procedure::PrepareSession(options.protocol_file, options.participant, session_seed, options.display_profile, group);
  const protocol::Protocol& protocol = prepared.protocol;
  if (observer) procedure::CheckObserverCanAnswer(*observer, protocol);
  // A new session's balanced group is decided again in the transaction that starts it: a station starting at the
  // same moment may take the group peeked above. So each group it may get is prepared (and checked) now.
  const bool balanced = protocol.groups && protocol.groups->assign == protocol::GroupAssign::kBalanced &&
                        !options.resume && !stays;
  std::map<std::string, procedure::PreparedSession> other_groups;
  if (balanced)
    for (const std::string& name : protocol.groups->names)
      if (name != prepared.group) {
        procedure::PreparedSession other = prepared;
        procedure::PrepareParticipant(&other, options.participant, session_seed, name);
        other_groups.emplace(name, std::move(other));
      }
  const std::string& protocol_text = prepared.protocol_text;
  const uint64_t seed = prepared.seed;
  const std::optional<calib::SceneCalib>& scene = prepared.scene;
  const bool window = !observer || options.window;
  const std::unique_ptr<render::GlContext> context = OpenDisplay(options, protocol, window, observer.has_value());
  StimulusRenderer renderer(protocol, scene, prepared.images, prepared.presentation);
  // The capture folder is checked before the session starts: a path that cannot hold captures stops here.
  if (!options.capture_dir.empty()) CheckCaptureFolder(options.capture_dir, protocol.name, options.participant);

  Recording record = Recording::Open(options.db);
  const SessionInfo meta = DescribeSession(options, prepared, *context, window, observer, info, balanced, session_number);
  if (!options.again && !options.resume) {
    // Running a participant through a study they finished is usually a typo in the id: say so.
    const std::vector<int64_t> done = record.CompletedSessions(protocol.name, options.participant);
    if (!done.empty())
      throw InputError(options.db.string(), "participant " + options.participant + " already completed " +
                                                protocol.name + " (session " + std::to_string(done.front()) +
                                                "); check the id, or add --again for another session");
  }
  const SessionStart start = record.StartOrResumeSession(protocol.name, options.participant, protocol_text,
                                                                seed, meta, options.resume);
  // The group the record gave (another than the one peeked when a station started at the same moment).
  const auto given = other_groups.find(start.group);
  const procedure::PreparedSession& chosen = given == other_groups.end() ? prepared : given->second;
  // A new session saves its list; a resumed one must show the same trials in the same order.
  if (start.trial_count == 0)
    record.SaveTrialList(start.session_id, chosen);
  else
    record.CheckTrialList(start.session_id, chosen);
  // The frames go to the window or stay headless (captured or not); the answers come from the keys or the observer.
  const cv::Size screen(protocol.display.width_px, protocol.display.height_px);
  const int band = chosen.presentation.prompt_band_px;
  std::unique_ptr<GlPresenter> shows;
  if (window)
    shows = std::make_unique<WindowPresenter>(*context, renderer, screen, band);
  else
    shows = std::make_unique<HeadlessPresenter>(
        *context, renderer,
        options.sim_fps > 0 ? options.sim_fps : chosen.images.take ? chosen.images.take->fps() : 4.0, band);
  std::optional<CapturingPresenter> capture;
  if (!options.capture_dir.empty()) capture.emplace(*shows, chosen, options.capture_dir, options.participant);
  Presenter& presenter = capture ? static_cast<Presenter&>(*capture) : *shows;
  KeyResponder keys(*context);
  std::optional<ObserverResponder> simulated;
  if (observer)
    simulated.emplace(*observer, chosen.seed, chosen.protocol, chosen.presentation,
                      KeyMap{chosen.protocol.responses, chosen.protocol.layout == protocol::Layout::kOddOneOut},
                      window ? &keys : nullptr);
  Responder& responder = simulated ? static_cast<Responder&>(*simulated) : keys;
  RunResult result =
      RunTrials({options.db, options.stop_after, options.progress}, chosen, presenter, responder, record, start);
  result.session_number = start.session_number;
  result.blur_note = procedure::UndeterminedBlurNote(chosen);
  if (start.session_number == 1)
    for (const std::string& code : record.CodesDifferingInCase(protocol.name, options.participant))
      result.ids_like += (result.ids_like.empty() ? "" : ", ") + code;
  return result;
}

}  // namespace blurcue::session
