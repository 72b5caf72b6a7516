// The CI side of the fuzzing (issue 8): every fuzz entry point replays its committed
// seed corpus tests/fuzz/corpus/<name>/ (seeds and the regression inputs of crashes
// found by libFuzzer) plus deterministic mutations of every seed. A crash, sanitizer
// report or invariant failure aborts the test binary. MOCAP_FUZZ_MUTATIONS overrides the
// number of mutations per seed (default 600: a few seconds in total, also under ASan);
// MOCAP_FUZZ_SAVE=FILE writes every input to FILE before running it, so that after a
// crash FILE holds the input to add to the corpus as a regression seed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "tests/fuzz/fuzz_mutate.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/support/test_support.h"

namespace mocap::fuzz {
namespace {

void run_one(const FuzzTarget& t, const std::vector<std::uint8_t>& input) {
  static const char* save = std::getenv("MOCAP_FUZZ_SAVE");
  if (save != nullptr) {
    std::ofstream f(save, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(input.data()),
            static_cast<std::streamsize>(input.size()));
  }
  t.entry(input.data(), input.size());
}

int mutations_per_seed() {
  const char* s = std::getenv("MOCAP_FUZZ_MUTATIONS");
  return s ? std::atoi(s) : 600;
}

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f),
                                   std::istreambuf_iterator<char>());
}

class FuzzCorpus : public ::testing::TestWithParam<FuzzTarget> {};

TEST_P(FuzzCorpus, SeedsAndMutationsRunClean) {
  const FuzzTarget& t = GetParam();
  const std::filesystem::path dir =
      std::filesystem::path(test::source_dir()) / "tests/fuzz/corpus" / t.name;
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  std::vector<std::filesystem::path> seeds;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) seeds.push_back(e.path());
  std::sort(seeds.begin(), seeds.end());
  ASSERT_GE(seeds.size(), 2u) << "corpus of " << t.name << " too small";
  // The detector is the costliest entry point (a detector and an image per input): a
  // third of the mutations keeps its share of the CI time in line with the others.
  const int n =
      std::string(t.name) == "blob_detector" ? mutations_per_seed() / 3 : mutations_per_seed();
  std::size_t runs = 0;
  for (const auto& p : seeds) {
    const std::vector<std::uint8_t> seed = read_bytes(p);
    SCOPED_TRACE(p.filename().string());
    run_one(t, seed);
    ++runs;
    const std::uint64_t base = fnv1a(p.filename().string());
    for (int i = 0; i < n; ++i) {
      const std::vector<std::uint8_t> m = mutate(seed, base + static_cast<std::uint64_t>(i));
      run_one(t, m);
      ++runs;
    }
  }
  EXPECT_EQ(runs, seeds.size() * static_cast<std::size_t>(n + 1));
}

INSTANTIATE_TEST_SUITE_P(Fuzz, FuzzCorpus, ::testing::ValuesIn(kFuzzTargets),
                         [](const ::testing::TestParamInfo<FuzzTarget>& i) {
                           return std::string(i.param.name);
                         });

}  // namespace
}  // namespace mocap::fuzz
