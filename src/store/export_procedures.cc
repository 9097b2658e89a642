#include "store/export_procedures.h"

#include "core/atomic_file.h"
#include "store/procedures.h"

namespace blurcue::store {

std::string WriteProcedures(Database& db, const std::filesystem::path& out_dir) {
  const std::vector<ProcedureColumn>& columns = ProcedureColumns();
  std::string text = CsvLine(CsvHeader(columns));
  Statement rows(db, "SELECT " + CsvSelect(columns, "pr") +
                         " FROM procedures pr JOIN protocol_versions pv ON pv.id = pr.protocol_version_id "
                         "JOIN studies st ON st.id = pv.study_id ORDER BY st.name, pv.id, pr.block");
  while (rows.Step()) text += CsvLine(CsvCells(columns, rows));
  WriteFileAtomically(out_dir / "procedures.csv", text);
  return CsvCodebook("procedures.csv", columns);
}

}  // namespace blurcue::store
