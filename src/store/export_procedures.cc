#include "store/export_procedures.h"

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
       "staircase's start, min, max, up, down, steps, stop_reversals; QUEST+'s stimuli, thresholds, slopes, lapses "
       "(its grid, uniform prior) and guess"},
  };
  return columns;
}

namespace {

Json ParametersOf(const protocol::Procedure& p) {
  Json out = {{"procedure", protocol::ToString(p.kind)}, {"variable", protocol::ToString(p.variable)},
              {"reference", p.reference}, {"trials", p.trials}};
  switch (p.kind) {
    case protocol::ProcedureKind::kStaircase:
      out.update({{"start", p.start}, {"min", p.min}, {"max", p.max}, {"up", p.up}, {"down", p.down},
                  {"steps", p.steps}, {"stop_reversals", p.stop_reversals}});
      break;
    case protocol::ProcedureKind::kQuestPlus:
      out.update({{"stimuli", p.stimuli}, {"thresholds", p.thresholds}, {"slopes", p.slopes}, {"lapses", p.lapses},
                  {"guess", p.guess}});
      break;
  }
  return out;
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
      // The files it names were checked when it ran; their absence here says nothing about the procedure. The
      // conditions tables a version recorded beside its text (protocol::RecordedText) are no field of a protocol.
      Json text = Json::parse(versions.GetText(2));
      if (text.is_object()) text.erase("recorded_conditions");
      parsed = protocol::ParseProtocol(text, "protocol.json", protocol::ValidateOptions{false});
    } catch (const std::exception&) {
      // A text the parser refuses (an older blurcue's; a block reading a conditions table, whose file is not here):
      // no parameters to give; the analysis says its intervals are not determined.
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
    codebook += CsvLine({"procedures.csv", c.name, c.type, c.unit, c.allowed, c.meaning, ""});
  return codebook;
}

}  // namespace blurcue::store
