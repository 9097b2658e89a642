#pragma once
// synth-scene's and synth-take's errors in the words a user typed (synth_scene_command.cc).
#include <map>
#include <string>

#include "core/error.h"

namespace blurcue::cli {

// An Error(kInput) naming a synth::SceneOptions field ("focus_mm: ...") as the option a user typed ("--focus-mm:
// ...", kUsage); `renamed` adds or overrides field -> option names. Other errors pass unchanged.
Error AsSceneOptionError(const Error& e, const std::map<std::string, std::string>& renamed = {});

}  // namespace blurcue::cli
