#pragma once
// Names an experimenter writes, checked against the names the code reads: the nearest one, for a did-you-mean.
#include <cstddef>
#include <string>
#include <vector>

namespace blurcue {

// Edit distance between `a` and `b`: insertions, deletions, substitutions of one byte and swaps of two
// neighbouring bytes each count one (optimal string alignment), so "gird" is one slip from "grid".
size_t EditDistance(const std::string& a, const std::string& b);

// The candidate `name` was probably meant to be, "" when none is near: first one that differs only in case
// (Measured -> measured, left -> Left), else the nearest by edit distance ignoring case (a swap of neighbours is one
// edit: egde -> edge), if at most 2 and less than half of `name`'s length (so a short name is not
// "corrected" into an unrelated one), else the one candidate that `name` (3 characters or more) abbreviates
// (int -> integer). Ties: the earlier candidate.
std::string NearestName(const std::string& name, const std::vector<std::string>& candidates);

// " (did you mean X?)" for the nearest candidate, "" when none is near or `name` is itself a candidate.
std::string DidYouMean(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace blurcue
