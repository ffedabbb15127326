// The main() every benchmark program shares: it runs the program's run_bench and reports an error on one
// line, named after the program, with exit code 1.
#include <cstdio>
#include <exception>
#include <string>

int run_bench(int argc, char** argv);

int main(int argc, char** argv) {
  try {
    return run_bench(argc, argv);
  } catch (const std::exception& e) {
    const std::string program = argc > 0 ? argv[0] : "lacuna bench";
    std::fprintf(stderr, "%s: %s\n", program.substr(program.find_last_of('/') + 1).c_str(), e.what());
    return 1;
  }
}
