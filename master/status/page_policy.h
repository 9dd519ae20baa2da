#pragma once
// The Content-Security-Policy of the operator's page, made from the page
// itself: its inline script and style may run, by their SHA-256, and nothing
// else (markup slipped into the page runs nothing), it may ask this server for
// data and nothing else, and no other page may frame it.

#include <string>
#include <string_view>

namespace optique::master {

// For `html`, whose <script> and <style> elements are inline (each hashed as
// it stands between its tags).
[[nodiscard]] std::string page_security_policy(std::string_view html);

}  // namespace optique::master
