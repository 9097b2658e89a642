#include "core/names.h"

#include <gtest/gtest.h>

namespace blurcue {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(EditDistance("secton", "section"), 1u);    // one insertion
  EXPECT_EQ(EditDistance("section", "secton"), 1u);    // one deletion
  EXPECT_EQ(EditDistance("edge", "edgy"), 1u);         // one substitution
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("same", "same"), 0u);
}

// Two neighbouring letters swapped are one slip: "gird" for grid got no did-you-mean (two edits of a four-letter
// name), as content.type "gird" showed the adversary.
TEST(EditDistance, ASwapOfNeighboursIsOneEdit) {
  EXPECT_EQ(EditDistance("gird", "grid"), 1u);
  EXPECT_EQ(EditDistance("sectoin", "section"), 1u);
  EXPECT_EQ(EditDistance("ab", "ba"), 1u);
  EXPECT_EQ(EditDistance("abc", "ca"), 3u);  // no substring is edited twice (optimal string alignment)
  EXPECT_EQ(NearestName("gird", {"grid", "ball", "picture"}), "grid");
  EXPECT_EQ(NearestName("xy", {"yx"}), "");  // still less than half of a two-letter name
}

TEST(NearestName, CaseSlipWinsOverAnEditDistanceTie) {
  // "left" is one substitution from "lefT" and from "Left" alike; the case slip is the one meant.
  EXPECT_EQ(NearestName("left", {"lefx", "Left"}), "Left");
  EXPECT_EQ(NearestName("Measured", {"none", "measured", "estimated"}), "measured");
  EXPECT_EQ(NearestName("Edge", {"edge", "section"}), "edge");
}

TEST(NearestName, NearestWithinTwoEditsIgnoringCase) {
  EXPECT_EQ(NearestName("secton", {"edge", "section", "speed_cm_s"}), "section");
  EXPECT_EQ(NearestName("difference_arcmins", {"relative_difference", "difference_arcmin"}), "difference_arcmin");
  EXPECT_EQ(NearestName("Sectoin", {"section"}), "section");  // a swap of neighbours; case ignored
}

// Two neighbouring letters swapped is one edit, so a short name gets its did-you-mean too.
TEST(NearestName, SwappedNeighboursInAShortName) {
  EXPECT_EQ(NearestName("egde", {"edge", "section", "speed_cm_s"}), "edge");
  EXPECT_EQ(NearestName("ei", {"id"}), "");  // 2 letters: not a slip of anything
  EXPECT_EQ(NearestName("dei", {"id", "die"}), "die");
}

// An abbreviation of one candidate (3 characters or more) names it; one of two names neither.
TEST(NearestName, AbbreviationOfExactlyOneCandidate) {
  EXPECT_EQ(NearestName("int", {"integer", "number", "choice", "text"}), "integer");
  EXPECT_EQ(NearestName("Num", {"integer", "number", "choice", "text"}), "number");
  EXPECT_EQ(NearestName("mea", {"measured", "measured_section", "none"}), "");
  EXPECT_EQ(NearestName("me", {"measured"}), "");
}

TEST(NearestName, NothingNearGivesEmpty) {
  EXPECT_EQ(NearestName("colour", {"edge", "section"}), "");
  EXPECT_EQ(NearestName("", {"edge"}), "");
  // Two edits turn any two letters into "id": a short name is not corrected into an unrelated one.
  EXPECT_EQ(NearestName("xy", {"id"}), "");
  EXPECT_EQ(NearestName(std::string(1000, 'e'), {"edge"}), "");
}

TEST(DidYouMean, SaysTheNearestOrNothing) {
  EXPECT_EQ(DidYouMean("secton", {"edge", "section"}), " (did you mean section?)");
  EXPECT_EQ(DidYouMean("section", {"edge", "section"}), "");
  EXPECT_EQ(DidYouMean("colour", {"edge", "section"}), "");
}

}  // namespace
}  // namespace blurcue
