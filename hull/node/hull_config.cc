// The hull service's options and its definition for runtime::service_main (hull_node.h).
#include "hull_node.h"
#include "yaml_io/options.h"
#include "yaml_io/rig_yaml.h"

namespace studio::hull {

Expected<void> HullNodeOptions::validate() const {
  if (box.size() != 6) return fail("box: expected 6 numbers x0,y0,z0,x1,y1,z1");
  if (auto g = grid_spec().validate(); !g) return g;
  if (min_cameras < 1) return fail("min_cameras: must be >= 1");
  if (actor_prefix.empty() || actor_prefix.size() > 40)
    return fail("actor_prefix: 1..40 characters");
  if (projector_mask_step < 1 || projector_mask_step > 64)
    return fail("projector_mask_step: must be in 1..64");
  return {};
}

GridSpec HullNodeOptions::grid_spec() const {
  GridSpec g;
  if (box.size() == 6) {
    g.box_min = Eigen::Vector3d(box[0], box[1], box[2]);
    g.box_max = Eigen::Vector3d(box[3], box[4], box[5]);
  }
  g.axis = axis;
  g.cells_u = grid;
  g.cells_v = grid;
  return g;
}

runtime::ServiceDefinition hull_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "hull";
  d.summary =
      "Real-time line-segment visual hull: masks of every camera -> per-actor segments and mesh.";
  d.config_help =
      "  hull:                     (required section)\n"
      "    rig: FILE               rig.yaml with the cameras (relative to the config file)\n"
      "    box: [x0,y0,z0,x1,y1,z1] reconstruction volume, studio frame, metres\n"
      "    grid: 128               columns per side (8..2048)\n"
      "    axis: y                 continuous axis of the segments: x|y|z\n"
      "    deadline_ms: 40         wait for a frame's missing masks at most this long\n"
      "    min_cameras: 2          drop a frame with fewer masks at its deadline\n"
      "    min_views: 2            actor = inside every silhouette that sees it AND seen by\n"
      "                            >= min_views cameras (0..64; see studio-hull offline --help)\n"
      "    threads: 2              threads of the cut and of the exact crossings\n"
      "    mesh: true              publish studio/actor/mesh\n"
      "    refine: true            exact crossings on the mesh (else half-cell vertices)\n"
      "    mesh_normals: false     publish vertex normals with the mesh (receivers that need\n"
      "                            them compute them: the preview; the projector never does)\n"
      "    min_actor_volume: 0.01  smaller components (m^3) are noise\n"
      "    actor_prefix: actor     actor ids <prefix>0, <prefix>1, ... largest first\n"
      "    projector_masks: false  publish studio/projector/mask: for every projector of the\n"
      "                            rig, the projector pixels the actors cover (viewpoint cut,\n"
      "                            eq. 7-8), one sample per frame and projector; the\n"
      "                            projectors' own studio/projector/calibration join or\n"
      "                            replace the rig's (projector_calibrations_in)\n"
      "    projector_mask_step: 2  the cut samples every step-th projector pixel (1..64)\n"
      "  Status (studio/service/status): where a frame's time goes, ms, running means:\n"
      "  capture_to_mask_ms (capture -> its last mask written), stage_mask_delivery_ms (written\n"
      "  -> handled), stage_queue_ms, stage_cut_ms,\n"
      "  stage_mesh_ms, stage_refine_ms, stage_publish_ms, mask_to_mesh_ms (last mask handled ->\n"
      "  last mesh written); see hull/node/hull_stages.h.\n";
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto section = config.required("hull");
    if (!section) return std::unexpected(section.error());
    static const yaml::Schema<HullNodeOptions> schema{
        yaml::field("rig", &HullNodeOptions::rig).required().relative_path(),
        yaml::field("box", &HullNodeOptions::box).required().size(6),
        yaml::field("grid", &HullNodeOptions::grid).range(8, 2048),
        yaml::enum_field("axis", &HullNodeOptions::axis,
                         {{"x", Axis::x}, {"y", Axis::y}, {"z", Axis::z}}),
        yaml::field("deadline_ms", &HullNodeOptions::deadline_ms).range(1, 1000),
        yaml::field("min_cameras", &HullNodeOptions::min_cameras).range(1, 64),
        yaml::field("min_views", &HullNodeOptions::min_views).range(0, 64),
        yaml::field("threads", &HullNodeOptions::threads).range(1, 64),
        yaml::field("mesh", &HullNodeOptions::mesh),
        yaml::field("refine", &HullNodeOptions::refine),
        yaml::field("mesh_normals", &HullNodeOptions::mesh_normals),
        yaml::field("min_actor_volume", &HullNodeOptions::min_actor_volume).min(0),
        yaml::field("actor_prefix", &HullNodeOptions::actor_prefix),
        yaml::field("projector_masks", &HullNodeOptions::projector_masks),
        yaml::field("projector_mask_step", &HullNodeOptions::projector_mask_step).range(1, 64),
    };
    auto options = schema.read(*section);
    if (!options) return std::unexpected(options.error());
    auto rig = yaml::read_rig(options->rig);
    if (!rig) return std::unexpected(rig.error());
    std::vector<Camera> projectors;
    for (const Projector& p : rig->projectors) projectors.push_back(p.camera);
    return make_hull_node(*options, rig->cameras, ctx, std::move(projectors));
  };
  return d;
}

}  // namespace studio::hull
