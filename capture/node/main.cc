// studio-capture: the capture server (issue 3 item 7).
//   studio-capture --config capture.yaml     the node (runtime::service_main)
//   studio-capture verify-take DIR           check a recorded take and rebuild its index
#include <signal.h>

#include <cstring>

#include "capture_node.h"
#include "verify_take.h"

int main(int argc, char** argv) {
  using namespace studio::capture::node;
  if (argc >= 2 && std::strcmp(argv[1], "verify-take") == 0) return verify_take_main(argc, argv);
  ::signal(SIGXFSZ,
           SIG_IGN);  // a file size limit (ulimit -f) ends a take with EFBIG, not the server
  return studio::runtime::service_main(argc, argv, capture_service_definition());
}
