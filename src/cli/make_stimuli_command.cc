#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "render/stimuli.h"

namespace blurcue::cli {

void AddMakeStimuliCommand(CLI::App& app) {
  auto out = std::make_shared<std::string>("stimuli");
  CLI::App* cmd = app.add_subcommand(
      "make-stimuli",
      "Draw the study's stimulus textures (procedural, deterministic, 8-bit sRGB PNG):\n"
      "  soccer.png  2048 x 1024 equirectangular soccer ball (truncated icosahedron) for the balls of tests 2-3\n"
      "  wood.png    2048 x 1024 equirectangular wood grain (seed 1), the alternative ball texture\n"
      "  grid.png    1024 x 1024 white card with a 5 x 5 black grid, the virtual content of test 1\n"
      "  face.png    800 x 1200 face picture with alpha, the pre-research's depth-matching content\n"
      "Example: blurcue make-stimuli --out stimuli");
  cmd->add_option("--out", *out, "folder to write into (created if needed)")->capture_default_str();
  cmd->callback([out] {
    for (const auto& file : render::WriteStandardStimuli(*out)) std::printf("wrote %s\n", file.string().c_str());
  });
}

}  // namespace blurcue::cli
