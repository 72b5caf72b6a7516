// Fuzz-style test of the Foxglove protocol handler (the bytes a viewer can send): seed
// messages, deterministic mutations of them (tests/fuzz/fuzz_mutate.h) and random byte
// strings, bounded iterations. Invariants: never throws or crashes (ASan/UBSan in CI), a
// refusal always has a one-line reason, and the subscription table never holds more
// than one subscription per advertised channel nor a channel that was not advertised.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pipeline/foxglove/protocol.h"
#include "tests/fuzz/fuzz_mutate.h"

namespace mocap::foxglove {
namespace {

const std::vector<std::string>& seeds() {
  static const std::vector<std::string> s = {
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":2}]})",
      R"({"op":"unsubscribe","subscriptionIds":[0,1]})",
      R"({"op":"subscribe","subscriptions":[{"id":4294967295,"channelId":3}]})",
      R"({"op":"getParameters","parameterNames":[],"id":"x"})",
      R"({"op":"subscribe","subscriptions":[{"id":1e3,"channelId":-0}]})",
      R"([{"op":"subscribe"}])",
      R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":1,"channelId":2}]})",
      R"({"op":"unsubscribe","subscriptionIds":[[[[[[[[[0]]]]]]]]]})",
      "\"\\ud800\"",
  };
  return s;
}

void check_invariants(const ClientProtocol& p, bool ok) {
  if (!ok) {
    ASSERT_FALSE(p.error().empty());
    ASSERT_EQ(p.error().find('\n'), std::string::npos);
  }
  int total = 0;
  for (std::uint32_t channel : {1u, 2u, 3u}) {
    std::uint32_t sub = 0;
    total += p.subscription_for(channel, sub) ? 1 : 0;
  }
  std::uint32_t sub = 0;
  ASSERT_FALSE(p.subscription_for(4, sub));
  ASSERT_EQ(total, p.subscription_count());
}

TEST(FoxgloveFuzz, MutatedSeedsNeverBreakTheHandler) {
  int accepted = 0;
  for (std::size_t s = 0; s < seeds().size(); ++s) {
    const std::vector<std::uint8_t> seed(seeds()[s].begin(), seeds()[s].end());
    for (std::uint64_t i = 0; i < 1500; ++i) {
      const auto bytes = fuzz::mutate(seed, fuzz::fnv1a(seeds()[s]) ^ i);
      const std::string text(bytes.begin(), bytes.end());
      ClientProtocol p({1, 2, 3});
      // A session: the mutated message after a valid subscription, then the seed again.
      ASSERT_TRUE(p.on_text(seeds()[0]));
      const bool ok = p.on_text(text);
      accepted += ok ? 1 : 0;
      check_invariants(p, ok);
      check_invariants(p, p.on_text(seeds()[s]));
      check_invariants(p, p.on_binary(bytes.size()));
    }
  }
  // The mutations are not all rejected: the handler's accepting paths are exercised too.
  EXPECT_GT(accepted, 0);
}

TEST(FoxgloveFuzz, RandomBytesNeverBreakTheHandler) {
  fuzz::SplitMix64 rng(20261201);
  for (int i = 0; i < 4000; ++i) {
    std::string text(rng.below(200), '\0');
    for (char& c : text) c = static_cast<char>(rng.next());
    if (i % 2 == 0 && !text.empty()) text[0] = '{';
    ClientProtocol p({1, 2, 3});
    check_invariants(p, p.on_text(text));
  }
  // Deep nesting is refused before parsing, at any size.
  ClientProtocol p({1});
  EXPECT_FALSE(p.on_text(std::string(60000, '[')));
  EXPECT_FALSE(p.on_text("{\"op\":\"subscribe\",\"subscriptions\":" + std::string(30000, '[')));
}

}  // namespace
}  // namespace mocap::foxglove
