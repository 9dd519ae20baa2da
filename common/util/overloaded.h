#pragma once
// std::visit with one lambda per alternative: std::visit(Overloaded{[](A&) {…}, [](B&) {…}}, v).

namespace optique::util {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace optique::util
