#pragma once
// The hull service (issue 5 item 5): subscribes the masks of every camera of the rig on
// studio/camera/mask, assembles one frame (waiting at most `deadline_ms` after its first mask;
// late or missing cameras are counted and reported), cuts the line-segment visual hull, splits it
// into actors (connected components) and publishes, per actor, studio/actor/segments and
// studio/actor/mesh stamped with the frame and the masks' capture_ns. Cameras start from the rig
// file and follow studio/camera/calibration (tracked cameras send one per frame).
//
// Status: besides the loop's counters, where each frame's time goes (hull_stages.h gauges).
//
// Config (the `hull:` section of the service config; see hull_service_definition()):
//   rig: rig.yaml             cameras (required; relative to the config file)
//   box: [x0,y0,z0,x1,y1,z1]  the reconstruction volume, studio frame, metres (required)
//   grid: 128                 columns per side (8..2048)
//   axis: y                   continuous axis of the segments (x|y|z)
//   deadline_ms: 40           wait for a frame's missing masks at most this long
//   min_cameras: 2            fewer masks than this at the deadline: the frame is dropped
//   min_views: 2              visibility policy (hull/silhouette_cut.h): a point is actor iff
//                             inside every silhouette that sees it and seen by >= min_views
//                             cameras (0..64; the offline CLI's default, kDefaultMinViews)
//   threads: 2                threads of the cut, the segment marching cubes and the exact
//                             crossings (columns, halves of the cell rows and crossing vertices
//                             are independent)
//   mesh: true                publish studio/actor/mesh (segment marching cubes)
//   refine: true              exact crossings on the mesh (hull/crossing_refine.h): vertices
//                             between an inside and an outside column move to where the hull
//                             really ends instead of half a cell
//   mesh_normals: false       publish vertex normals with the mesh (the wire allows none; the
//                             preview computes them, the projector never uses them): 25 % of
//                             the sample and their computation off the mesh's path
//   min_actor_volume: 0.01    components smaller than this (m^3) are noise, not actors
//   actor_prefix: actor       actor ids are <prefix>0, <prefix>1, ... largest first
//   projector_masks: false    per frame, for every projector of the rig, its actor mask by the
//                             viewpoint cut (hull/projector_mask.h, eq. 7-8) on
//                             studio/projector/mask (keyed by projector_id, the masks' frame and
//                             capture_ns), after the frame's segments and meshes
//   projector_mask_step: 2    the cut samples every step-th projector pixel (1..64)

#include <memory>
#include <string>
#include <vector>

#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"
#include "runtime/service.h"

namespace studio::hull {

struct HullNodeOptions {
  std::string rig;
  std::vector<double> box;
  int grid = 128;
  Axis axis = Axis::y;
  double deadline_ms = 40;
  int min_cameras = 2;
  int min_views = kDefaultMinViews;
  int threads = 2;
  bool mesh = true;
  bool refine = true;
  bool mesh_normals = false;
  double min_actor_volume = 0.01;
  std::string actor_prefix = "actor";
  bool projector_masks = false;
  int projector_mask_step = 2;

  Expected<void> validate() const;
  GridSpec grid_spec() const;
};

runtime::ServiceDefinition hull_service_definition();

// Builds the node (rig already read) — exposed for tests that host nodes in-process.
// `projectors`: the rig's projectors (inverse cameras), used when options.projector_masks.
Expected<std::unique_ptr<runtime::Node>> make_hull_node(const HullNodeOptions& options,
                                                        std::vector<Camera> cameras,
                                                        runtime::NodeContext& context,
                                                        std::vector<Camera> projectors = {});

}  // namespace studio::hull
