#include "sewn/cmap/indexed_message.hpp"

namespace sewn {

IndexedMessage& IndexedMessage::operator<<(const std::string& text) {
  texts_.back() += text;
  return *this;
}

IndexedMessage& IndexedMessage::operator<<(CellRef c) {
  refs_.push_back({Ref::Kind::cell, c.index});
  texts_.emplace_back();
  return *this;
}

IndexedMessage& IndexedMessage::operator<<(PointRef p) {
  refs_.push_back({Ref::Kind::point, p.index});
  texts_.emplace_back();
  return *this;
}

IndexedMessage& IndexedMessage::operator<<(MaterialRef m) {
  refs_.push_back({Ref::Kind::material, m.index});
  texts_.emplace_back();
  return *this;
}

IndexedMessage& IndexedMessage::operator<<(const IndexedMessage& more) {
  texts_.back() += more.texts_[0];
  refs_.insert(refs_.end(), more.refs_.begin(), more.refs_.end());
  texts_.insert(texts_.end(), more.texts_.begin() + 1, more.texts_.end());
  return *this;
}

std::string IndexedMessage::render(const std::function<std::string(const Ref&)>& name) const {
  std::string out = texts_[0];
  for (std::size_t k = 0; k < refs_.size(); ++k) out += name(refs_[k]) + texts_[k + 1];
  return out;
}

IndexedMessage IndexedMessage::renumbered(const std::function<Ref(const Ref&)>& to) const {
  IndexedMessage out = *this;
  for (Ref& r : out.refs_) r = to(r);
  return out;
}

std::string IndexedMessage::str() const {
  static constexpr const char* words[] = {"cell ", "point ", "material "};
  return render([](const Ref& r) { return words[static_cast<int>(r.kind)] + std::to_string(r.index); });
}

}  // namespace sewn
