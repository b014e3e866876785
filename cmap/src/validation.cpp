#include "sewn/cmap/validation.hpp"

#include <sstream>

namespace sewn {

const char* to_string(ValidationIssue::Kind k) {
  switch (k) {
    case ValidationIssue::Kind::dangling_link: return "dangling link";
    case ValidationIssue::Kind::beta0_beta1: return "beta0/beta1 not inverse";
    case ValidationIssue::Kind::not_involution: return "not an involution";
    case ValidationIssue::Kind::composition: return "composition not an involution";
    case ValidationIssue::Kind::attribute_mismatch: return "attribute mismatch in a cell";
    case ValidationIssue::Kind::attribute_dead: return "dart refers to a dead attribute";
    case ValidationIssue::Kind::attribute_count: return "attribute reference count";
    case ValidationIssue::Kind::attribute_orphan: return "orphan attribute";
    case ValidationIssue::Kind::attribute_two_cells: return "attribute shared by two cells";
    case ValidationIssue::Kind::attribute_dart: return "attribute's dart";
    case ValidationIssue::Kind::free_list: return "free list";
    case ValidationIssue::Kind::marks: return "marks";
  }
  return "?";
}

void ValidationReport::add(ValidationIssue::Kind k, std::uint32_t dart, int index, std::string message) {
  ++total_;
  if (issues_.size() < limit_) issues_.push_back({k, dart, index, std::move(message)});
}

std::string ValidationReport::str(std::size_t max_lines) const {
  if (ok()) return "valid";
  std::ostringstream os;
  os << total_ << " invariant violation" << (total_ == 1 ? "" : "s") << ":\n";
  std::size_t n = 0;
  for (const auto& i : issues_) {
    if (n++ == max_lines) break;
    os << "  [" << to_string(i.kind) << "] " << i.message << '\n';
  }
  if (total_ > n) os << "  ... and " << (total_ - n) << " more\n";
  return os.str();
}

std::ostream& operator<<(std::ostream& os, const ValidationReport& r) { return os << r.str(); }

}  // namespace sewn
