#pragma once
// studio-hull offline --refine / --texture: the post-production path (issue 21, docs/offline.md).
// Per frame of a recorded take: hull -> photo-consistent refinement (offline/photo_carve.h) ->
// mesh -> vertex colours blended from the cameras (offline/texture.h) -> <name>_<frame>.glb;
// then the index <name>.gltf once every frame of the take is written. Farm-ready: --frames A:B
// shards, frames already written and verified are skipped, files are written atomically and
// byte-identical whatever the sharding or the threads.

namespace studio::hull::cli {

// True when argv (after "offline") asks for this mode (--refine, --texture, --plan, --index-only).
bool wants_refined(int argc, char** argv);
// Usage text of the mode (part of studio-hull offline --help).
const char* refined_usage();
// Runs the mode; exit status as documented in the usage.
int run_refined(int argc, char** argv);

}  // namespace studio::hull::cli
