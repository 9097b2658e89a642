#include "procedure/visibility.h"

#include <gtest/gtest.h>

#include "protocol/level.h"

namespace blurcue::procedure {
namespace {

// validate --plan's and preview's label of a trial's levels: an object level by its id, else by its members as
// trials.csv names it - never as the JSON object it was written as ('comparison {"left":"measured",...}' it said).
TEST(LevelsLabel, NamesAnObjectLevelByItsIdElseByItsMembers) {
  protocol::Trial t;
  t.levels = {protocol::LevelOf("comparison", Json{{"right", "estimated"}, {"left", "measured"}}),
              protocol::LevelOf("edge", Json(3)),
              protocol::LevelOf("pattern", Json{{"id", 2}, {"speed_cm_s", 1.8}})};
  EXPECT_EQ(LevelsLabel(t), "comparison left=measured;right=estimated edge 3 pattern 2");
}

}  // namespace
}  // namespace blurcue::procedure
