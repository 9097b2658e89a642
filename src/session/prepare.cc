#include "session/prepare.h"

#include <algorithm>

#include "core/error.h"
#include "core/json_io.h"

namespace blurcue::session {

PreparedSession PrepareStudy(const std::filesystem::path& protocol_file, const std::filesystem::path& display_profile) {
  PreparedSession s;
  // Read once: the text recorded with the session is the text that was validated.
  s.protocol_text = ReadTextFile(protocol_file);
  s.protocol = protocol::ParseProtocol(ParseJson(s.protocol_text, protocol_file.string()), protocol_file);
  s.scene = LoadProtocolScene(s.protocol);
  s.images = LoadStimulusImages(s.protocol, s.scene);
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
  return s;
}

void PrepareParticipant(PreparedSession* s, const std::string& participant, std::optional<uint64_t> seed,
                        const std::string& group) {
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
  for (const protocol::Trial& trial : s->trials)
    s->scenes.push_back(DescribeTrial(s->protocol, trial, s->scene ? &*s->scene : nullptr, &s->presentation));
  CheckRealPhotos(s->protocol, s->scenes, &s->real_photos_checked);
  // Each pair trial's blur plan on that screen: one radius, or per pixel by depth where the object's depth asks.
  if (s->scene)
    for (TrialScene& scene : s->scenes) PlanOnScreen(s->protocol, *s->scene, s->presentation, &scene);
}

PreparedSession PrepareSession(const std::filesystem::path& protocol_file, const std::string& participant,
                               std::optional<uint64_t> seed, const std::filesystem::path& display_profile,
                               const std::string& group) {
  PreparedSession s = PrepareStudy(protocol_file, display_profile);
  PrepareParticipant(&s, participant, seed, group);
  return s;
}

}  // namespace blurcue::session
