// The known name closest to a misspelled one (edit distance), for messages that say "did you mean".
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace birkhoff_cart {

/// Levenshtein distance: the fewest single-character insertions, deletions and substitutions
/// that turn `a` into `b`.
std::size_t edit_distance(const std::string& a, const std::string& b);

/// The candidate nearest to `name` by edit_distance, if it is within max(2, |name| / 3) edits
/// (a typo, not another word); "" otherwise. Ties go to the first candidate.
std::string closest_name(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace birkhoff_cart
