#pragma once
// Which between-subject groups `validate` and `preview` check: every group, so that no group's trials go unchecked,
// or the one --group names.
#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"
#include "protocol/protocol.h"

namespace blurcue::cli {

// The groups to check: every group of a protocol with groups (in the file's order), or only `group` when it is given;
// {""} for a protocol without groups. Throws Error(kUsage) naming --group for a name the protocol does not have (with
// the nearest name as did-you-mean) or for --group on a protocol without groups.
inline std::vector<std::string> GroupsToCheck(const protocol::Protocol& p, const std::string& group) {
  // The name as typed, cut as every echoed value is (a 5000-character --group was a 5067-character message), and
  // quoted when a space at either end would otherwise not show ("--group  : ...").
  const bool padded = !group.empty() && (std::isspace(static_cast<unsigned char>(group.front())) ||
                                          std::isspace(static_cast<unsigned char>(group.back())));
  const std::string shown = Echo(group, padded);
  if (!p.groups) {
    if (!group.empty())
      throw Error(ErrorKind::kUsage, "--group " + shown + ": " + p.file.string() + " has no groups");
    return {""};
  }
  const std::vector<std::string>& names = p.groups->names;
  if (group.empty()) return names;
  if (std::find(names.begin(), names.end(), group) != names.end()) return {group};
  // Did you mean: a case slip first (NearestName), else the name fewest single-character edits away.
  std::string nearest = NearestName(group, names);
  size_t best = std::string::npos;
  if (nearest.empty())
    for (const std::string& name : names)
      if (const size_t d = EditDistance(group, name); d < best) best = d, nearest = name;
  std::string listed;
  for (const std::string& name : names) listed += (listed.empty() ? "" : ", ") + name;
  throw Error(ErrorKind::kUsage, "--group " + shown + ": " + p.file.string() + " has no such group (did you mean " +
                                     nearest + "? its groups: " + listed + ")");
}

}  // namespace blurcue::cli
