#pragma once
// Looking into the actions a protocol core returns (master/protocol.h,
// node/protocol.h): those of one kind, the first of a kind, whether a log line
// says something.

#include <string>
#include <variant>
#include <vector>

namespace optique::testing {

template <class T, class Actions>
std::vector<const T*> all_of(const Actions& actions) {
  std::vector<const T*> found;
  for (const auto& a : actions) {
    if (const T* t = std::get_if<T>(&a)) found.push_back(t);
  }
  return found;
}

template <class T, class Actions>
const T* first(const Actions& actions) {
  const auto found = all_of<T>(actions);
  return found.empty() ? nullptr : found.front();
}

// Whether one of the actions' Log lines (type Log) contains `fragment`.
template <class Log, class Actions>
bool logged(const Actions& actions, const std::string& fragment) {
  for (const Log* l : all_of<Log>(actions)) {
    if (l->text.find(fragment) != std::string::npos) return true;
  }
  return false;
}

}  // namespace optique::testing
