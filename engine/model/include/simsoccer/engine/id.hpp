// Typed ids: robots, articulations and bodies are numbered separately, and
// an id of one kind cannot be passed where another is expected (that would
// take two user conversions). Built from and read as its integer, so loops
// and indexing stay plain; a deliberate change of kind is written out
// (`ArticulationId(robot)`).
#pragma once

#include <cstdint>
#include <functional>

namespace simsoccer::engine {

template <typename Tag>
class Id {
 public:
  constexpr Id() = default;
  constexpr Id(uint32_t value) : value_(value) {}  // implicit: ids are numbers
  constexpr operator uint32_t() const { return value_; }
  constexpr uint32_t value() const { return value_; }
  constexpr Id& operator++() {
    ++value_;
    return *this;
  }
  constexpr Id operator++(int) {
    const Id old = *this;
    ++value_;
    return old;
  }

 private:
  uint32_t value_ = 0;
};

}  // namespace simsoccer::engine

template <typename Tag>
struct std::hash<simsoccer::engine::Id<Tag>> {
  size_t operator()(simsoccer::engine::Id<Tag> id) const noexcept {
    return std::hash<uint32_t>{}(id.value());
  }
};
