// Design: subcommands of the `mocap` executable register themselves, so each command
// lives in its own cmd_<name>.cpp (compiled into the executable, not a library, so the
// static registrars are always linked). A command parses its flags with CLI11 and
// calls library code; it reports failures as one line on stderr and an exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace mocap::app {

// Adds the subcommand to `app`; its callback stores the process exit code in exit_code.
using RegisterCommandFn = void (*)(CLI::App& app, int& exit_code);

struct CommandRegistrar {
  // `order` sorts the commands in --help.
  CommandRegistrar(int order, RegisterCommandFn fn) noexcept;
};

void register_all_commands(CLI::App& app, int& exit_code);

// Prints "mocap: <message>" on stderr and returns the exit code for bad input (2).
int fail(const std::string& message);

}  // namespace mocap::app
