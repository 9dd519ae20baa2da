#pragma once
// A log record is one line of text a person reads on a terminal, and much of what
// is logged comes from peers (a node's id in an unauthenticated hello, goodbye and
// refusal reasons, a tracker's datagrams, HTTP requests): a newline in it would
// forge a record, an ESC sequence would reach the operator's terminal. So the
// logger escapes them in every message before any sink sees it.

#include <string>
#include <string_view>

namespace optique::log {

// Whether `text` holds anything escape_for_log() changes; false for the usual
// printable ASCII, which is passed on without a copy.
[[nodiscard]] bool needs_escaping(std::string_view text);

// `text` with every control character (C0 — \n \r \t as such, others as \xHH —,
// DEL, C1 as \u0080…), the Unicode line and paragraph separators and the
// bidirectional overrides (which reorder what a terminal shows) escaped, and each
// byte of invalid UTF-8 written as \xHH. A backslash is left as it is: the text
// stays readable, and a peer that sends "\n" as two characters forges nothing.
[[nodiscard]] std::string escape_for_log(std::string_view text);

}  // namespace optique::log
