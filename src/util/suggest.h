// "Did you mean" suggestions for misspelled names and keys, the same everywhere a user types one.
#pragma once

#include <string>
#include <vector>

namespace lacuna {

// The closest candidate to `word` by edit distance (a candidate that only adds "_mm" first), or ""
// when none is close enough.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

// "; did you mean \"<closest>\"?" for the closest candidate to `word`, or "" when none is close
// enough: the suffix every message about an unknown name ends with.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace lacuna
