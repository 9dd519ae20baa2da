#include <exception>
#include <iostream>

#include "node/cli.h"

// optique-node: the node protocol and the null renderer; a GL node continues as
// optique-node-gl (node/gl/main.cpp).
int main(int argc, char** argv) {
  try {
    return optique::node::run_cli(argc, argv, {});
  } catch (const std::exception& e) {
    std::cerr << "optique-node: fatal: " << e.what() << "\n";
    return 1;
  }
}
