// Entry point of `mocap`: one executable, one subcommand per task (simulate, track,
// calibrate, run, ...). Each subcommand registers itself (see command_registry.h).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

#include "app/command_registry.h"

namespace mocap::app {
namespace {
std::vector<std::pair<int, RegisterCommandFn>>& registry() {
  static std::vector<std::pair<int, RegisterCommandFn>> r;
  return r;
}
}  // namespace

CommandRegistrar::CommandRegistrar(int order, RegisterCommandFn fn) noexcept {
  try {
    registry().emplace_back(order, fn);
  } catch (...) {
    std::fputs("mocap: out of memory at start-up\n", stderr);
  }
}

void register_all_commands(CLI::App& app, int& exit_code) {
  auto entries = registry();
  std::sort(entries.begin(), entries.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& e : entries) e.second(app, exit_code);
}

int fail(const std::string& message) {
  std::fprintf(stderr, "mocap: %s\n", message.c_str());
  return 2;
}

}  // namespace mocap::app

int main(int argc, char** argv) {
  CLI::App app{"mocap: real-time optical motion capture tracker for robots"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "mocap 0.1.0");
  int exit_code = 0;
  try {
    mocap::app::register_all_commands(app, exit_code);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    return mocap::app::fail(std::string("unexpected error: ") + e.what());
  }
  return exit_code;
}
