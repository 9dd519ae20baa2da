// Messages after the handshake, sealed (net/session_seal.h): what opens and what
// does not — another key, a changed byte, a replay, a reordering, a frame lost.

#include "net/session_seal.h"

#include <gtest/gtest.h>

#include <string>

namespace optique::net {
namespace {

std::vector<std::uint8_t> bytes(const std::string& text) { return {text.begin(), text.end()}; }

SessionKeys keys(std::uint8_t fill = 1, const std::string& id = "wall") {
  return derive_session_keys(Secret{std::vector<std::uint8_t>(32, fill)}, std::vector<std::uint8_t>(32, 2),
                             std::vector<std::uint8_t>(32, 3), id, 7);
}

TEST(SessionKeys, EachDirectionHasItsOwnKeyAndEveryInputCounts) {
  const SessionKeys k = keys();
  EXPECT_NE(k.to_node, k.to_master);
  EXPECT_EQ(k.to_node, keys().to_node) << "both sides derive the same";
  EXPECT_NE(k.to_node, keys(9).to_node) << "the secret";
  EXPECT_NE(k.to_node, keys(1, "other").to_node) << "the node id";
  const Secret secret{std::vector<std::uint8_t>(32, 1)};
  EXPECT_NE(k.to_node, derive_session_keys(secret, std::vector<std::uint8_t>(32, 4), std::vector<std::uint8_t>(32, 3),
                                           "wall", 7)
                           .to_node)
      << "the master's nonce";
  EXPECT_NE(k.to_node, derive_session_keys(secret, std::vector<std::uint8_t>(32, 2), std::vector<std::uint8_t>(32, 4),
                                           "wall", 7)
                           .to_node)
      << "the node's nonce";
  EXPECT_THROW((void)derive_session_keys(Secret{}, {}, {}, "wall", 7), std::invalid_argument);
}

TEST(SessionSeal, WhatIsSealedOpensInOrderAndIsNotPlain) {
  Sealer sealer(keys().to_node);
  Opener opener(keys().to_node);
  for (const std::string text : {"frame begin", "", "swap"}) {
    const std::vector<std::uint8_t> sealed = sealer.seal(bytes(text));
    ASSERT_EQ(sealed.size(), text.size() + kSealTagBytes);
    if (!text.empty()) {
      EXPECT_EQ(std::string(sealed.begin(), sealed.end()).find(text), std::string::npos);
    }
    const auto opened = opener.open(sealed);
    ASSERT_TRUE(opened) << opened.error();
    EXPECT_EQ(opened.value(), bytes(text));
  }
}

TEST(SessionSeal, ForgedChangedReplayedReorderedOrMissingFramesDoNotOpen) {
  const SessionKey key = keys().to_master;
  Sealer sealer(key);
  const auto first = sealer.seal(bytes("ready 1"));
  const auto second = sealer.seal(bytes("ready 2"));
  {
    Opener opener(keys(9).to_master);
    EXPECT_FALSE(opener.open(first)) << "another secret";
  }
  {
    Opener opener(keys().to_node);
    EXPECT_FALSE(opener.open(first)) << "the other direction's key";
  }
  for (std::size_t i = 0; i < first.size(); ++i) {
    auto changed = first;
    changed[i] ^= 0x01;
    Opener opener(key);
    EXPECT_FALSE(opener.open(changed)) << "byte " << i;
  }
  {
    Opener opener(key);
    ASSERT_TRUE(opener.open(first));
    const auto replayed = opener.open(first);
    ASSERT_FALSE(replayed) << "replayed";
    EXPECT_NE(replayed.error().find("failed authentication"), std::string::npos) << replayed.error();
  }
  {
    Opener opener(key);
    EXPECT_FALSE(opener.open(second)) << "reordered, or the first lost";
  }
  {
    Opener opener(key);
    EXPECT_FALSE(opener.open(std::vector<std::uint8_t>(kSealTagBytes - 1, 0))) << "too short for a tag";
    EXPECT_FALSE(opener.open(bytes("a plain message, not sealed at all"))) << "plain";
  }
}

}  // namespace
}  // namespace optique::net
