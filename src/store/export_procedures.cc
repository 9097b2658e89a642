#include "store/export_procedures.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>

#include "core/json_io.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "protocol/protocol.h"
#include "protocol/vocabulary.h"

namespace blurcue::store {

const std::vector<ColumnDef>& ProcedureColumns() {
  static const std::vector<ColumnDef> columns = {
      {"study", "string", "", "", "the study (protocol name)"},
      {"protocol_hash", "string", "", "16 hex digits", "the protocol version, as trials.csv's protocol_hash"},
      {"block", "integer", "", "", "the block's index in the protocol, as trials.csv's block"},
      {"block_name", "string", "", "", "the block's name"},
      {"procedure", "string", "", "staircase|quest_plus", "the adaptive procedure"},
      {"parameters", "string", "", "JSON",
       "the procedure's parameters as the protocol parser reads them: procedure, variable, reference, trials; a "
       "staircase's start, min, max, up, down, steps, stop_reversals and guess (1/n of an odd one out's n intervals, else "
       "0.5); QUEST+'s stimuli, thresholds, slopes, lapses "
       "(its grid, uniform prior) and guess"},
  };
  return columns;
}

namespace {

Json ParametersOf(const protocol::Procedure& p) {
  Json out = {{"procedure", protocol::ToString(p.kind)}, {"variable", protocol::ToString(p.variable)},
              {"reference", protocol::ToJson(std::optional<protocol::BlurSpec>(p.reference))}, {"trials", p.trials}};
  switch (p.kind) {
    case protocol::ProcedureKind::kStaircase:
      out.update({{"start", p.start}, {"min", p.min}, {"max", p.max}, {"up", p.up}, {"down", p.down},
                  {"steps", p.steps}, {"stop_reversals", p.stop_reversals}, {"guess", p.guess}});
      break;
    case protocol::ProcedureKind::kQuestPlus:
      out.update({{"stimuli", p.stimuli}, {"thresholds", p.thresholds}, {"slopes", p.slopes}, {"lapses", p.lapses},
                  {"guess", p.guess}});
      break;
  }
  return out;
}

// A recorded text as it parsed when it ran. Its conditions tables (protocol::RecordedText keeps them beside the text
// as "recorded_conditions", no field of a protocol; a video study's take is "recorded_take") are written where the text's paths find them from a protocol file
// in a fresh folder, deep enough for every leading "../", and the folder is removed afterwards. The files a protocol
// names otherwise were checked when it ran and are not read here.
protocol::Protocol ParseRecorded(Json text) {
  Json tables = Json::object();
  if (text.is_object() && text.contains("recorded_conditions")) {
    tables = text["recorded_conditions"];
    text.erase("recorded_conditions");
  }
  if (text.is_object()) text.erase("recorded_take");  // the take a video study ran on (stimulus::TakeIdentity)
  const protocol::ValidateOptions no_files{false};
  if (!tables.is_object() || tables.empty()) return protocol::ParseProtocol(text, "protocol.json", no_files);
  size_t depth = 0;
  for (const auto& item : tables.items()) {
    const std::filesystem::path path = std::filesystem::path(item.key()).lexically_normal();
    if (path.is_absolute()) throw Error(ErrorKind::kInput, "an absolute conditions path: " + item.key());
    size_t up = 0;
    for (const auto& part : path) up += part == "..";
    depth = std::max(depth, up);
  }
  static std::atomic<int> counter{0};
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("blurcue-procedures-" + std::to_string(::getpid()) + "-" + std::to_string(++counter));
  struct Remove {
    std::filesystem::path path;
    ~Remove() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } remove{dir};
  std::filesystem::path base = dir;
  for (size_t i = 0; i < depth; ++i) base /= "d";
  std::filesystem::create_directories(base);
  for (const auto& item : tables.items()) {
    const std::filesystem::path target = (base / item.key()).lexically_normal();
    std::filesystem::create_directories(target.parent_path());
    std::ofstream out(target, std::ios::binary);
    out << (item.value().is_string() ? item.value().get<std::string>() : std::string());
    if (!out) throw Error(ErrorKind::kInput, "cannot write " + target.string());
  }
  return protocol::ParseProtocol(text, base / "protocol.json", no_files);
}

}  // namespace

std::string WriteProcedures(Database& db, const std::filesystem::path& out_dir) {
  std::vector<std::string> header;
  for (const auto& c : ProcedureColumns()) header.push_back(c.name);
  std::string text = CsvLine(header);
  Statement versions(db, "SELECT st.name, pv.hash, pv.json FROM protocol_versions pv JOIN studies st ON "
                         "st.id = pv.study_id ORDER BY st.name, pv.id");
  while (versions.Step()) {
    protocol::Protocol parsed;
    try {
      parsed = ParseRecorded(ParseJson(versions.GetText(2), "protocol"));
    } catch (const std::exception&) {
      // A text the parser refuses (an older blurcue's): no parameters to give; the analysis says its intervals are
      // not determined.
      continue;
    }
    for (size_t b = 0; b < parsed.blocks.size(); ++b) {
      const protocol::Block& block = parsed.blocks[b];
      if (!block.procedure) continue;
      text += CsvLine({versions.GetText(0), versions.GetText(1), std::to_string(b), block.name,
                       protocol::ToString(block.procedure->kind), ParametersOf(*block.procedure).dump()});
    }
  }
  WriteFileAtomically(out_dir / "procedures.csv", text);
  std::string codebook;
  for (const auto& c : ProcedureColumns())
    codebook += CodebookRow("procedures.csv", c);
  return codebook;
}

}  // namespace blurcue::store
