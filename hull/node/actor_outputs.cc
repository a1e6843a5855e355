#include "actor_outputs.h"

#include "core/log.h"
#include "hull/crossing_refine.h"
#include "hull/projector_mask.h"
#include "hull/segment_mesh.h"
#include "wire/actor_convert.h"
#include "wire/convert.h"
#include "wire/sample.h"

namespace studio::hull {
namespace {

constexpr const char* kLog = "hull";

// Straight from the mesh's arrays (3 packed floats / indices per element) into the sample's.
void mesh_to_wire(const Mesh& mesh, studio_ActorMesh& s) {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  static_assert(sizeof(std::array<uint32_t, 3>) == 3 * sizeof(uint32_t));
  const auto floats = [](const std::vector<Eigen::Vector3f>& v) {
    return std::span<const float>(v.empty() ? nullptr : v.front().data(), 3 * v.size());
  };
  wire::assign(s.vertices, floats(mesh.vertices));
  wire::assign(s.normals, floats(mesh.normals));
  wire::assign(s.triangles, std::span<const uint32_t>(
                                mesh.triangles.empty() ? nullptr : mesh.triangles.front().data(),
                                3 * mesh.triangles.size()));
}

}  // namespace

ActorOutputs::ActorOutputs(runtime::ServiceLoop& loop, const HullNodeOptions& options)
    : options_(options) {
  if (options_.projector_masks)
    projector_masks_ =
        &loop.output<studio_ProjectorMask>({.counter = "projector_masks_out", .rate = false});
  segs_ = &loop.output<studio_SegmentSet>({.counter = "segment_sets_out"});
  meshes_ = &loop.output<studio_ActorMesh>({.counter = "meshes_out", .rate = false});
}

void ActorOutputs::actor(const SegmentSet& set, const std::string& actor_id, FrameId frame,
                         std::span<const View> views, const CutOptions& cut, Durations& d) {
  auto t = std::chrono::steady_clock::now();
  const auto lap = [&t](Duration& into) {
    const auto now = std::chrono::steady_clock::now();
    into += now - t;
    t = now;
  };
  wire::Owned<studio_SegmentSet> s;
  wire::set(s->actor_id, actor_id);
  s->frame = frame.frame;
  s->capture_ns = frame.capture_ns;
  wire::from_core(set, *s);
  (void)segs_->write(*s);
  lap(d.publish);
  if (!options_.mesh) return;
  wire::Owned<studio_ActorMesh> m;
  wire::set(m->actor_id, actor_id);
  m->frame = frame.frame;
  m->capture_ns = frame.capture_ns;
  m->source_frame = frame.frame;
  // Normals only when published (mesh_normals); with exact crossings they come after the
  // vertices moved (refine_crossings). On the node's threads, as the cut and the crossings.
  const bool normals = options_.mesh_normals;
  Mesh mesh = segment_marching_cubes(
      set, {.normals = normals && !options_.refine, .threads = options_.threads});
  lap(d.mesh);
  if (options_.refine) {
    // Only fails on a mask of the wrong size, which the frame's cut already rejected.
    if (auto ok = refine_crossings(mesh, set, views, cut, normals); !ok) {
      STUDIO_LOG(warn, kLog) << "frame " << frame.frame << ": " << ok.error().message;
      if (normals) compute_normals(mesh);
    }
    lap(d.refine);
  }
  mesh_to_wire(mesh, *m);
  (void)meshes_->write(*m);
  lap(d.publish);
}

void ActorOutputs::dispose(const std::string& actor_id) {
  wire::Owned<studio_SegmentSet> s;
  wire::set(s->actor_id, actor_id);
  (void)segs_->dispose(*s);
  wire::Owned<studio_ActorMesh> m;
  wire::set(m->actor_id, actor_id);
  (void)meshes_->dispose(*m);
}

void ActorOutputs::projector_masks(FrameId frame, std::span<const Camera> projectors,
                                   std::span<const View> views, const CutOptions& cut) {
  if (!projector_masks_) return;
  const GridSpec g = options_.grid_spec();
  ProjectorMaskOptions po;
  po.step = options_.projector_mask_step;
  po.cut = cut;
  for (const Camera& projector : projectors) {
    auto mask = projector_mask(projector, Eigen::AlignedBox3d(g.box_min, g.box_max), views, po);
    if (!mask) {
      STUDIO_LOG(warn, kLog) << "frame " << frame.frame << ": projector " << projector.id << ": "
                             << mask.error().message;
      continue;
    }
    wire::Owned<studio_ProjectorMask> s;
    wire::set(s->projector_id, projector.id);
    s->frame = frame.frame;
    s->capture_ns = frame.capture_ns;
    s->step = uint32_t(po.step);
    wire::from_core(*mask, *s);
    (void)projector_masks_->write(*s);
  }
}

}  // namespace studio::hull
