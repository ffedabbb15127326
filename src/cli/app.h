// The `lacuna` command line: parses arguments and dispatches to the commands.
#pragma once

namespace lacuna {

// Runs the program with the given arguments and returns its exit code (see cli/exit_codes.h).
int run_app(int argc, char** argv);

}  // namespace lacuna
