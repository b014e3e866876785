#pragma once
// The report returned by CMap::validate(): every broken invariant, each naming its dart.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace sewn {

/// One violated invariant.
struct ValidationIssue {
  enum class Kind {
    dangling_link,        ///< β points outside the map or to a dead dart
    beta0_beta1,          ///< β0 is not the inverse of β1
    not_involution,       ///< βi(βi(d)) ≠ d, or βi(d) = d, for i ≥ 2
    composition,          ///< βi∘βj is not an involution for i+2 ≤ j
    attribute_mismatch,   ///< two darts of one cell carry different attributes
    attribute_dead,       ///< a dart refers to a freed attribute slot
    attribute_count,      ///< an attribute's reference count differs from its darts
    attribute_orphan,     ///< a live attribute no dart refers to
    attribute_two_cells,  ///< one attribute shared by darts of two different cells
    attribute_dart,       ///< an attribute's recorded dart is dead or belongs to another cell
    free_list,            ///< the free list is broken (cycle, live dart on it, wrong length)
    marks,                ///< a dart marked for an unreserved mark, or a wrong marked count
  };
  Kind kind;
  std::uint32_t dart;       ///< the dart where the violation was seen (or null)
  int index;                ///< the β index or attribute dimension involved (-1 if none)
  std::string message;      ///< a sentence naming dart, β and values
};

/// All violations found. Empty means the map is valid. Printing gives one line per issue.
class ValidationReport {
 public:
  [[nodiscard]] bool ok() const { return issues_.empty(); }
  explicit operator bool() const { return ok(); }
  [[nodiscard]] const std::vector<ValidationIssue>& issues() const { return issues_; }
  /// At most `max_lines` lines, then a count of the rest.
  [[nodiscard]] std::string str(std::size_t max_lines = 50) const;
  void add(ValidationIssue::Kind k, std::uint32_t dart, int index, std::string message);
  /// Stops recording after this many issues (the count still grows).
  void set_limit(std::size_t n) { limit_ = n; }
  [[nodiscard]] std::size_t total() const { return total_; }

 private:
  std::vector<ValidationIssue> issues_;
  std::size_t limit_ = 1000;
  std::size_t total_ = 0;
};

std::ostream& operator<<(std::ostream& os, const ValidationReport& r);
const char* to_string(ValidationIssue::Kind k);

}  // namespace sewn
