// The refusal of a name outside a fixed set: the known name closest to a misspelled one (edit
// distance), for messages that say "did you mean", and the message that lists the known ones.
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

/// `names` joined by ", ": the list a refusal names.
std::string name_list(const std::vector<std::string>& names);

/// The refusal of a name outside a fixed set: "unknown WHAT 'NAME' (known: A, B)", or, when NAME is a
/// typo of B, "unknown WHAT 'NAME' (known: A, B; did you mean 'B'?)".
std::string unknown_name_message(const std::string& what, const std::string& name,
                                 const std::vector<std::string>& known);

}  // namespace birkhoff_cart
