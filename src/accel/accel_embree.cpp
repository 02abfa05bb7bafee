// The one place that includes Embree.
#include "accel/accel.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace pl {
namespace {

const char* errorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
  }
  return "unrecognised error";
}

// Embree reports errors through this callback; we remember the last one and turn it into a
// pl::Error at the next check point (throwing through Embree's C frames is not allowed).
struct ErrorState {
  RTCError code = RTC_ERROR_NONE;
  std::string message;
};

void onEmbreeError(void* user, RTCError code, const char* message) {
  auto* state = static_cast<ErrorState*>(user);
  state->code = code;
  state->message = message ? message : "";
}

RTCRay toRtcRay(const Ray& r) {
  RTCRay ray;
  ray.org_x = r.origin.x;
  ray.org_y = r.origin.y;
  ray.org_z = r.origin.z;
  ray.dir_x = r.direction.x;
  ray.dir_y = r.direction.y;
  ray.dir_z = r.direction.z;
  ray.tnear = r.tMin;
  ray.tfar = r.tMax;
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

RayHit fromRtc(const RTCRayHit& rh) {
  RayHit hit;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    hit.t = rh.ray.tfar;
    hit.mesh = rh.hit.geomID;
    hit.triangle = rh.hit.primID;
    hit.barycentrics = Vec2(rh.hit.u, rh.hit.v);
  }
  return hit;
}

/// What the alpha-mask filter of one mesh needs (the geometry's user data).
struct MaskedMesh {
  const Scene* scene = nullptr;
  uint32_t mesh = 0;
};

/// Embree's intersection and occlusion filter for meshes with alpha-masked materials: a
/// candidate hit whose coverage (scene.h coverageAt) is below its material's cutoff is
/// rejected (valid = 0), so traversal goes on past it. Single rays, packets and streams all
/// come through here, so they agree. Meshes without masks get no filter and pay nothing.
void alphaMaskFilter(const RTCFilterFunctionNArguments* args) {
  const auto* masked = static_cast<const MaskedMesh*>(args->geometryUserPtr);
  const Scene& scene = *masked->scene;
  const Mesh& mesh = scene.meshes[masked->mesh];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t triangle = RTCHitN_primID(args->hit, args->N, i);
    const Material& material = scene.materials[mesh.materials[triangle]];
    if (!material.isMasked()) continue;
    const Vec2 barycentrics(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (coverageAt(scene, masked->mesh, triangle, barycentrics) < material.alphaCutoff) args->valid[i] = 0;
  }
}

}  // namespace

struct Accel::Impl {
  ErrorState errors;
  /// Padded copies of vertex buffers that were not padded (see the constructor); empty for
  /// scenes that came out of Scene::finalize() unchanged.
  std::vector<std::vector<Vec3>> paddedPositions;
  /// User data of the alpha-mask filters (one per mesh with a masked material; stable addresses).
  std::vector<std::unique_ptr<MaskedMesh>> maskedMeshes;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  void check(const char* what) {
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE || errors.code != RTC_ERROR_NONE) {
      const RTCError shown = errors.code != RTC_ERROR_NONE ? errors.code : code;
      fail("Embree {} failed: {}{}{}", what, errorName(shown), errors.message.empty() ? "" : ": ", errors.message);
    }
  }
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

Accel::Accel(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) fail("Embree could not create a device: {}", errorName(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, &impl_->errors);

  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_NONE);
  scene.bounds(boundsMin_, boundsMax_);

  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Shared, not copied. Scene::finalize() padded `positions` so that Embree's 16-byte
    // read of the last vertex stays inside the allocation. A copy of a Scene loses that
    // spare capacity; rather than let Embree read 4 bytes past the end of the heap block,
    // such a mesh's positions are copied once into a padded buffer owned by the Accel.
    const Vec3* positions = mesh.positions.data();
    if (mesh.positions.capacity() < mesh.positions.size() + 1) {
      std::vector<Vec3>& copy = impl_->paddedPositions.emplace_back();
      copy.reserve(mesh.positions.size() + 1);
      copy.assign(mesh.positions.begin(), mesh.positions.end());
      positions = copy.data();
    }
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, positions, 0,
                               sizeof(Vec3), mesh.positions.size());
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                               sizeof(UVec3), mesh.triangles.size());
    const bool masked = std::any_of(mesh.materials.begin(), mesh.materials.end(),
                                    [&](uint32_t material) { return scene.materials[material].isMasked(); });
    if (masked) {
      auto& user = impl_->maskedMeshes.emplace_back(std::make_unique<MaskedMesh>(MaskedMesh{&scene, uint32_t(m)}));
      rtcSetGeometryUserData(geometry, user.get());
      rtcSetGeometryIntersectFilterFunction(geometry, alphaMaskFilter);
      rtcSetGeometryOccludedFilterFunction(geometry, alphaMaskFilter);
    }
    rtcCommitGeometry(geometry);
    // Geometry IDs equal mesh indices so a hit's geomID is the mesh directly.
    rtcAttachGeometryByID(impl_->scene, geometry, static_cast<unsigned>(m));
    rtcReleaseGeometry(geometry);
    impl_->check("geometry setup");
  }
  rtcCommitScene(impl_->scene);
  impl_->check("BVH build");
}

Accel::~Accel() = default;

bool Accel::intersect(const Ray& ray, RayHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray = toRtcRay(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  hit = fromRtc(rh);
  return hit.hit();
}

bool Accel::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = toRtcRay(ray);
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar = −inf on an occlusion hit
}

namespace {
/// Lane `lane` of a 16-ray packet = r.
void setPacketRay(RTCRay16& packet, size_t lane, const Ray& r) {
  packet.org_x[lane] = r.origin.x;
  packet.org_y[lane] = r.origin.y;
  packet.org_z[lane] = r.origin.z;
  packet.dir_x[lane] = r.direction.x;
  packet.dir_y[lane] = r.direction.y;
  packet.dir_z[lane] = r.direction.z;
  packet.tnear[lane] = r.tMin;
  packet.tfar[lane] = r.tMax;
  packet.time[lane] = 0.0f;
  packet.mask[lane] = 0xffffffffu;
  packet.id[lane] = static_cast<unsigned>(lane);
  packet.flags[lane] = 0;
}

/// The rays in 16-ray packets: for each packet, setPacketRay for all 16 lanes of `packet`
/// (an inactive lane — past the end — gets a copy of the packet's first ray and valid 0),
/// then trace(valid, first ray index, active lanes).
template <typename Trace>
void forEachPacket16(std::span<const Ray> rays, RTCRay16& packet, Trace&& trace) {
  alignas(64) int valid[16];
  for (size_t base = 0; base < rays.size(); base += 16) {
    const size_t n = std::min<size_t>(16, rays.size() - base);
    for (size_t i = 0; i < 16; ++i) {
      const bool active = i < n;
      valid[i] = active ? -1 : 0;
      setPacketRay(packet, i, rays[base + (active ? i : 0)]);
    }
    trace(valid, base, n);
  }
}
}  // namespace

void Accel::intersectCoherent(std::span<const Ray> rays, std::span<RayHit> hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRayHit16 packet;
  forEachPacket16(rays, packet.ray, [&](int* valid, size_t base, size_t n) {
    for (size_t i = 0; i < 16; ++i) {
      packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->scene, &context, &packet);
    for (size_t i = 0; i < n; ++i) {
      RayHit& hit = hits[base + i];
      hit = RayHit{};
      if (packet.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
        hit.t = packet.ray.tfar[i];
        hit.mesh = packet.hit.geomID[i];
        hit.triangle = packet.hit.primID[i];
        hit.barycentrics = Vec2(packet.hit.u[i], packet.hit.v[i]);
      }
    }
  });
}

void Accel::intersectIncoherent(std::span<const Ray> rays, std::span<RayHit> hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  constexpr size_t kChunk = 256;
  RTCRayHit stream[kChunk];
  for (size_t base = 0; base < rays.size(); base += kChunk) {
    const size_t n = std::min(kChunk, rays.size() - base);
    for (size_t i = 0; i < n; ++i) {
      stream[i].ray = toRtcRay(rays[base + i]);
      stream[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      stream[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect1M(impl_->scene, &context, stream, static_cast<unsigned>(n), sizeof(RTCRayHit));
    for (size_t i = 0; i < n; ++i) hits[base + i] = fromRtc(stream[i]);
  }
}

void Accel::occludedMany(std::span<const Ray> rays, std::span<uint8_t> occluded) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  constexpr size_t kChunk = 256;
  RTCRay stream[kChunk];
  for (size_t base = 0; base < rays.size(); base += kChunk) {
    const size_t n = std::min(kChunk, rays.size() - base);
    for (size_t i = 0; i < n; ++i) stream[i] = toRtcRay(rays[base + i]);
    rtcOccluded1M(impl_->scene, &context, stream, static_cast<unsigned>(n), sizeof(RTCRay));
    for (size_t i = 0; i < n; ++i) occluded[base + i] = stream[i].tfar < 0.0f ? 1 : 0;
  }
}

void Accel::occludedCoherent(std::span<const Ray> rays, std::span<uint8_t> occluded) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRay16 packet;
  forEachPacket16(rays, packet, [&](int* valid, size_t base, size_t n) {
    rtcOccluded16(valid, impl_->scene, &context, &packet);
    for (size_t i = 0; i < n; ++i) occluded[base + i] = packet.tfar[i] < 0.0f ? 1 : 0;  // −inf on a hit
  });
}

}  // namespace pl
