#include "cli/app.h"

int main(int argc, char** argv) { return lacuna::run_app(argc, argv); }
