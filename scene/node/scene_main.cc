// studio-scene --config scene.yaml: the virtual scene server (scene/node/scene_server.h).
// The renderer's `studio-scene render ...` subcommand is dispatched here before service_main once
// scene/render lands (its CLI owns that entry point).
#include "runtime/service.h"
#include "scene_server.h"

int main(int argc, char** argv) {
  return studio::runtime::service_main(argc, argv, studio::scene::node::service_definition());
}
