#include "core/names.h"

#include <algorithm>

namespace blurcue {

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
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
  // A case slip is the likeliest meaning whatever else is near: "Left" is what someone who wrote "left" meant.
  for (const auto& c : candidates)
    if (c != name && Lower(c) == lower) return c;
  // Two neighbouring letters swapped ("egde" for edge) is one slip, however short the name.
  for (const auto& c : candidates) {
    const std::string other = Lower(c);
    if (other.size() != lower.size() || other == lower) continue;
    size_t first = 0;
    while (other[first] == lower[first]) ++first;
    if (first + 1 < lower.size() && other[first] == lower[first + 1] && other[first + 1] == lower[first] &&
        other.compare(first + 2, std::string::npos, lower, first + 2, std::string::npos) == 0)
      return c;
  }
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
