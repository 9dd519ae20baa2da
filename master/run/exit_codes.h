#pragma once
// The exit statuses of optique-master and of the tools it runs, shared by the
// mains and the tests.

namespace optique::master {

inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 2;   // bad config or command line: nothing started
inline constexpr int kExitFailed = 3;  // could not run: no nodes, cannot listen, ...
// It ran, but too few frames were shown (master.min_presented; by default: none).
inline constexpr int kExitTooFewShown = 4;

}  // namespace optique::master
