// The observer model's closed form in C++ (procedure/observer.h ProbabilityCorrect2afc) against the table the report's
// independent Python implementation (analysis/prediction.py) is checked against too: the plan and the report's
// prediction speak of one model.
#include <cstdio>
#include "blurcue/source_dir.h"
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "procedure/observer.h"

namespace blurcue::procedure {
namespace {

TEST(ObserverModelTable, CppClosedFormMatchesTheSharedTable) {
  std::ifstream table(BLURCUE_SOURCE_DIR "/tests/data/observer-2afc.csv");
  ASSERT_TRUE(table) << "tests/data/observer-2afc.csv";
  const ObserverParams defaults = ParseObserver("sim");
  std::string line;
  int rows = 0;
  while (std::getline(table, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'r') continue;
    double a = 0, b = 0, p = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &a, &b, &p), 3) << line;
    EXPECT_NEAR(ProbabilityCorrect2afc(defaults, a, b), p, 1e-12) << "r_a " << a << ", r_b " << b;
    ++rows;
  }
  EXPECT_GE(rows, 10);
}

}  // namespace
}  // namespace blurcue::procedure
