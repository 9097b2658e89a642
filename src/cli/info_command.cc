// blurcue info: what this blurcue is and what it will use - version, data folders, the GL renderer, the record's
// schema and the Python the report runs.
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/media.h"
#include "render/gl_context.h"
#include "store/schema.h"

namespace blurcue::cli {
namespace {

// The first line a command prints (stdout and stderr), or "" when it cannot be run.
std::string FirstLine(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) return "";
  char line[512] = "";
  if (!std::fgets(line, sizeof line, pipe.get())) return "";
  std::string text = line;
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  struct Args {
    std::string python = "/usr/bin/python3";
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Print what this blurcue is and what it will use, and whether everything it needs is there.\n"
      "Its version, the folder it reads its shaders, stimuli, analysis and example protocols from (and how it found it: BLURCUE_DATA_DIR, installed beside the binary, or\n"
      "the source tree it was built from), the GL renderer an offscreen context gets, the record schema it writes,\n"
      "and the Python `blurcue report` runs with the packages it needs. Exit 0 when everything is there.\n"
      "Example: blurcue info");
  cmd->add_option("--python", args->python, "the Python `report` would run")->capture_default_str();
  cmd->callback([args] {
    bool ok = true;
    const DataDirectory& data = DataDir();
    std::printf("blurcue %s\n", BLURCUE_VERSION);
    std::printf("binary:    %s\n", ExecutableDir().string().c_str());
    std::printf("data:      %s (%s)\n", data.path.string().c_str(), data.origin.c_str());
    for (const char* part : {"shaders", "stimuli", "analysis", "protocols"}) {
      const bool there = std::filesystem::is_directory(data.path / part);
      ok = ok && there;
      std::printf("  %-9s %s%s\n", part, (data.path / part).string().c_str(), there ? "" : "  MISSING");
    }
    std::printf("record:    schema version %d\n", store::CurrentSchemaVersion());
    try {  // image files and videos (OpenCV's imgcodecs and videoio, loaded on first use)
      std::printf("media:     %s\n", media::PluginPath().c_str());
    } catch (const std::exception& e) {
      ok = false;
      std::printf("media:     not available: %s\n", e.what());
    }
    try {
      const auto context = render::GlContext::CreateOffscreen();
      std::printf("GL:        %s\n", context->Describe().c_str());
    } catch (const std::exception& e) {
      ok = false;
      std::printf("GL:        not available: %s\n", e.what());
    }
    const std::string version = FirstLine("'" + args->python + "' --version");
    const std::string packages =
        FirstLine("'" + args->python + "' -c \"import pandas, scipy, matplotlib, statsmodels; print('pandas ' + "
                  "pandas.__version__ + ', scipy ' + scipy.__version__ + ', matplotlib ' + matplotlib.__version__ + "
                  "', statsmodels ' + statsmodels.__version__)\"");
    const bool python_ok = version.rfind("Python", 0) == 0 && packages.rfind("pandas ", 0) == 0;
    ok = ok && python_ok;
    std::printf("python:    %s: %s; %s\n", args->python.c_str(), version.empty() ? "not found" : version.c_str(),
                python_ok ? packages.c_str() : ("analysis packages missing (" + packages + ")").c_str());
    if (!ok) throw Error(ErrorKind::kInput, "blurcue info: something above is missing");
  });
}

}  // namespace blurcue::cli
