#include "core/names.h"

#include <algorithm>

namespace blurcue {

size_t EditDistance(const std::string& a, const std::string& b) {
  // Three rows: a swap of two neighbouring bytes looks two rows back (optimal string alignment).
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    before.swap(previous);
    previous.swap(row);
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      row[j] = std::min({previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) row[j] = std::min(row[j], before[j - 2] + 1);
    }
  }
  return row[b.size()];
}

namespace {

// ASCII lower case only: names the code reads are ASCII, and a byte of a UTF-8 sequence must stay as it is.
std::string Lower(std::string text) {
  for (char& c : text)
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  return text;
}

}  // namespace

std::string NearestName(const std::string& name, const std::vector<std::string>& candidates) {
  // Validate reads names of at most a few hundred bytes; a longer one is no slip of a short name (and a distance over
  // it would cost its length times each candidate's).
  if (name.empty() || name.size() > 200) return "";
  const std::string lower = Lower(name);
  // A case slip is the likeliest meaning whatever else is near: "Yes" is what someone who wrote "yes" meant.
  for (const auto& c : candidates)
    if (c != name && Lower(c) == lower) return c;
  std::string best;
  size_t best_distance = 3;
  for (const auto& c : candidates) {
    if (c.size() > name.size() + 2 || name.size() > c.size() + 2) continue;  // the distance is at least 3
    const size_t d = EditDistance(lower, Lower(c));
    if (d < best_distance && 2 * d < name.size()) best_distance = d, best = c;
  }
  if (!best.empty() || name.size() < 3) return best;
  // An abbreviation of exactly one candidate: "int" for integer, "sim" for simulated.
  for (const auto& c : candidates) {
    if (c.size() <= name.size() || Lower(c).compare(0, lower.size(), lower) != 0) continue;
    if (!best.empty()) return "";  // it abbreviates two: neither is the likelier
    best = c;
  }
  return best;
}

std::string DidYouMean(const std::string& name, const std::vector<std::string>& candidates) {
  if (std::find(candidates.begin(), candidates.end(), name) != candidates.end()) return "";
  const std::string nearest = NearestName(name, candidates);
  return nearest.empty() ? "" : " (did you mean " + nearest + "?)";
}

}  // namespace blurcue
