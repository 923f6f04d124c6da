#pragma once
// Result<T, E>: a value or an error, the codec's way of saying "this input was bad" without
// throwing (C++17 has no std::expected). Accessing the wrong alternative is a programming
// error and is caught by assertions in debug builds only, never by exceptions.

#include <cassert>
#include <utility>
#include <optional>

namespace pmu::codec {

template <class E>
struct Unexpected {
  E error;
};
template <class E>
Unexpected(E) -> Unexpected<E>;

template <class T, class E>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  template <class G>
  Result(Unexpected<G> u) : error_(std::move(u.error)) {}  // NOLINT

  bool ok() const noexcept { return value_.has_value(); }
  explicit operator bool() const noexcept { return ok(); }

  const T& value() const& {
    assert(ok());
    return *value_;
  }
  T& value() & {
    assert(ok());
    return *value_;
  }
  T&& value() && {
    assert(ok());
    return std::move(*value_);
  }
  const T& operator*() const& { return value(); }
  const T* operator->() const { return &*value_; }

  const E& error() const& {
    assert(!ok());
    return error_;
  }

 private:
  // Both members, not a variant: E is a small aggregate and GCC's -Wnull-dereference
  // misfires on std::get_if chains.
  std::optional<T> value_;
  E error_{};
};

}  // namespace pmu::codec
