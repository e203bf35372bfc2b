// The vocabulary every layer of Core shares: builder, backend and filter kinds, the build and
// render parameters, statistics, the image and the recoverable error. Builders and backends
// include this header, never the Engine facade.
#pragma once
#include "Math.h"
#include "TransferFunction.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip {

/// How the render loop walks the skipping structure (the registry in Builders.h maps each
/// builder to one).
/// GridParts is Grid (and DistanceGrid) walking the parts of the bricks marked for it
/// (sub-brick masks, Classification.h): a backend draws a Grid frame with it where that pays.
enum class TraversalKind : int { Naive = 0, Grid = 1, Tree = 2, Hybrid = 3, GridParts = 4 };

enum class BuilderKind : int {
  Naive,          ///< no skipping (the paper's baseline)
  Grid,           ///< DDA over the macro-cell occupancy grid
  LBVH,           ///< paper 3.1 on the render backend's device (CUDA, or the oneTBB twin)
  LBVHCPU,        ///< paper 3.1, oneTBB
  KdTreeCPU,      ///< paper 3.2.1 (Vidal et al. 2008), oneTBB
  KdTreeGPU,      ///< paper 3.2.2, CUDA, host-driven recursion
  KdTreeGPUFast,  ///< ours: level-parallel CUDA k-d tree
  Hybrid,         ///< paper 3.3: shallow k-d tree + 16^3 grid
  DistanceGrid,   ///< ours: the Grid DDA leaping through empty space with a distance field
  Auto            ///< measures a few structures (Naive among them), the close ones twice, keeps the fastest
};
/// Empty (ours): Deep, but a leaf is kept or split by its empty space, not its size
/// (KdTreeSplit.h, kdEmptySplit); MLS is ignored.
enum class LeafCriterion : int { Shallow, Deep, Empty };
enum class BackendKind : int { Auto, CPU, CUDA };
enum class FilterMode : int { Exact, Hardware };
/// How a label map is sampled (RenderParams::labelSampling; render/LabelSampler.h, LabelMap.h).
enum class LabelSampling : int {
  /// The label of the voxel nearest the sample: blocky borders, one voxel a step.
  Nearest = 0,
  /// Of the labels of the 8 voxels around the sample, the one whose trilinear weights sum
  /// highest (argmax of the interpolated indicator functions): smooth borders; a label/background
  /// border lies where that label's own binary volume interpolates to 1/2. Never a label that is
  /// not among the 8 corners.
  Blend = 1
};

const char* builderName(BuilderKind b);
/// Accepts CLI names (naive, grid, lbvh, lbvh-cpu, kdtree-cpu, kdtree-gpu, kdtree-gpu-fast, hybrid,
/// distance-grid)
/// and the VTK property names (Naive, Grid, LBVH, KdTreeCPU, ...), case-insensitively.
bool parseBuilder(const std::string& s, BuilderKind& out);

struct BuildParams {
  BuilderKind builder = BuilderKind::Grid;
  LeafCriterion leaf = LeafCriterion::Deep;
  int maxLeafSize = 0;  ///< 0: none; else leaves' edge <= MLS cells (32 or 128 in the paper)
  /// KdTreeGPU/KdTreeGPUFast split candidates: >= 2: bins - 1 planes per node at multiples of
  /// len/bins (the paper's binned method); 0: sweep, every brick boundary along the longest axis,
  /// which builds exactly the KdTreeCPU tree. KdTreeCPU ignores it: it always sweeps (= bins 0).
  /// Engine::setBuildParams throws std::invalid_argument for 1 and negative values.
  int bins = 4;
  int brick = 8;        ///< macro-cell edge in cells (classification granularity)
  /// Builder Auto, progressive refinement: after an edit that changes the occupancy, when the
  /// kept structure took longer than this to build, the first frame is drawn with Grid (no build
  /// beyond classification) and the kept structure is rebuilt for the frame after. < 0: never.
  double autoQuickBuildSeconds = 1e-3;
  /// Builder Auto, where it measures: 1: on probes, reduced frames (1/4 of each axis or less, at
  /// most 128 pixels a side) of the same view drawn inside the frame that needs a decision, so
  /// the user's frames always draw with the best structure known and measuring costs a fraction
  /// of one frame; 0: on the user's frames, one candidate a frame (cheap where frames take
  /// milliseconds); -1 (default): probes on the CPU backend, frames on CUDA.
  int autoProbe = -1;
  bool operator==(const BuildParams& o) const {
    return builder == o.builder && leaf == o.leaf && maxLeafSize == o.maxLeafSize &&
           bins == o.bins && brick == o.brick && autoQuickBuildSeconds == o.autoQuickBuildSeconds &&
           autoProbe == o.autoProbe;
  }
  bool operator!=(const BuildParams& o) const { return !(*this == o); }
};

/// Most lights shading takes (RenderParams::lights; more: the first ones, with one warning).
constexpr int kMaxLights = 8;

/// A light as vtkGPUVolumeRayCastMapper reads a vtkLight, in the volume's world frame.
struct Light {
  bool positional = false;                ///< false: directional, from position towards focalPoint
  double position[3] = {0, 0, 1};
  double focalPoint[3] = {0, 0, 0};
  double ambient[3] = {0, 0, 0};          ///< colour * intensity (vtkLight's default ambient is black)
  double diffuse[3] = {1, 1, 1};
  double specular[3] = {1, 1, 1};
  double attenuation[3] = {1, 0, 0};      ///< positional: constant, linear, quadratic
  double coneAngle = 30;                  ///< positional: a spot light when <= 90 degrees
  double exponent = 1;                    ///< positional spot: falloff exponent
};

struct RenderParams {
  double sampleDistance = 0;   ///< world units; <= 0: half the smallest spacing
  double ertThreshold = 2.0;   ///< early ray termination at this alpha; > 1 disables
  bool jitter = false;
  unsigned jitterSeed = 0;
  FilterMode filter = FilterMode::Exact;
  bool countSamples = false;   ///< statistics: FrameStats::samples (costs a per-pixel buffer)
  /// vtkVolumeMapper cropping: six planes (xmin, xmax, ymin, ymax, zmin, zmax) in the volume's
  /// coordinates (origin + index * spacing) cut the box into 27 regions; region
  /// i + 3j + 9k is drawn when bit i + 3j + 9k of `croppingFlags` is set (0x2000: the
  /// sub-volume between the planes, VTK_CROP_SUBVOLUME).
  bool cropping = false;
  double croppingPlanes[6] = {0, 0, 0, 0, 0, 0};
  int croppingFlags = 0x2000;
  /// Clipping planes in the volume's world frame: a point x is kept where
  /// n.x + d >= 0 for every plane (nx, ny, nz, d), as vtkPlane's normal points to the kept side.
  std::vector<std::array<double, 4>> clipPlanes;
  /// The first sample lies this many sample distances past the ray's entry into the box (>= 0).
  /// vtkGPUVolumeRayCastMapper starts one step in (1) and takes that first sample even where the
  /// ray leaves the box before it (clamped to the box); > 0 does the same. 0: at the entry.
  double firstSampleOffset = 0;

  // Blend modes (vtkVolumeMapper::SetBlendMode semantics, as vtkGPUVolumeRayCastMapper does them).
  BlendMode blend = BlendMode::Composite;
  std::vector<double> isoValues;  ///< Isosurface: up to kMaxIsoValues (16); any order
  /// Additive and average: scalars are normalised to [0, 1] over this range (VTK uses the scalar
  /// array's range); lo >= hi: the transfer function's range.
  double scalarRange[2] = {0, 0};
  /// Average: only samples with value in this range count (vtkVolumeMapper's AverageIPScalarRange).
  double averageRange[2] = {-HUGE_VAL, HUGE_VAL};

  // Gradient shading (vtkVolumeProperty's Shade, Ambient, Diffuse, Specular, SpecularPower;
  // VTK's defaults), composite and isosurface modes only, as in VTK.
  bool shade = false;
  double ambient = 0.0, diffuse = 0.7, specular = 0.2, specularPower = 10.0;
  /// World direction from the volume towards a directional white light; (0,0,0): a headlight
  /// (VTK's default light: at the camera, so every ray is lit along itself).
  double lightDirection[3] = {0, 0, 0};

  // Lights other than VTK's default headlight (what vtkGPUVolumeRayCastMapper does with a
  // renderer's lights unless there is exactly one headlight of intensity 1, e.g. ParaView's light
  // kit): when `useLights`, shading sums over `lights` (the first kMaxLights), VTK's model, and
  // `lightDirection` is not used; no light at all shades black, as VTK does.
  bool useLights = false;
  std::vector<Light> lights;
  bool twoSidedLighting = true;  ///< vtkRenderer's TwoSidedLighting: back faces lit as front ones

  // Volumetric shadows and scattering (render/Scattering.h), as vtkGPUVolumeRayCastMapper (VTK
  // 9.2) draws them: shaded composite and isosurface frames, one shadow ray per light.
  double scatteringBlending = 0;       ///< VolumetricScatteringBlending in [0, 2]; 0: off
  double globalIlluminationReach = 0;  ///< GlobalIlluminationReach in [0, 1]: the shadow rays' length
  double scatteringAnisotropy = 0;     ///< vtkVolumeProperty's ScatteringAnisotropy in [-1, 1]
  /// Shading of four dependent components (RGBA): the component whose gradient lights a sample.
  /// vtkGPUVolumeRayCastMapper uses component 0 up to VTK 9.3 (ParaView 5.11's VTK 9.2) and
  /// component 3, the opacity, from VTK 9.4 on; two dependent components use component 0 in both.
  int rgbaLightingComponent = 0;

  // Slice blend mode: the plane through sliceOrigin with normal sliceNormal, in the volume's
  // world frame (as vtkPlane's origin and normal; a zero or non-finite normal: the plane through
  // the box centre normal to z, with one warning).
  double sliceOrigin[3] = {0, 0, 0};
  double sliceNormal[3] = {0, 0, 1};
  /// true: read the slice's sample where vtkGPUVolumeRayCastMapper (VTK 9.2 to 9.4) reads it: at
  /// the plane point's texture coordinate without its half-texel adjustment, i.e. index
  /// i (N+1)/N - 1/2 per axis (N cells), up to half a voxel off the plane (ParaView's images);
  /// false: at the plane point itself.
  bool sliceAsVTK = true;

  /// Nearest-voxel sampling instead of trilinear (vtkVolumeProperty's InterpolationType
  /// NEAREST), one-component volumes; the skipping is unchanged (the nearest voxel is one of a
  /// trilinear sample's corners).
  bool nearest = false;
  /// Label map (LabelMap.h): the volume's 8- or 16-bit integer values are label ids drawn with
  /// Engine::setLabelTable's colours and opacities (composite blending; the transfer function
  /// is kept for when this is off). Other voxel types: said once, drawn as an ordinary volume.
  bool labelMap = false;
  LabelSampling labelSampling = LabelSampling::Blend;
};
/// At most this many clipping planes (VTK's mappers take six).
constexpr int kMaxClipPlanes = 6;

/// Bounds on the work per ray (so a typo in Sample Distance cannot freeze ParaView's GUI).
/// The step is at least the smallest voxel spacing / kMinStepsPerVoxel; a ray through the whole
/// volume box takes at most kMaxSamplesPerCell samples per cell it can cross (cells along x + y
/// + z: a tiny spacing on one axis cannot make every ray long in samples) and never more than
/// kMaxSamplesPerRay (which also keeps every sample index exact in float); and the step is at
/// most half the box's diagonal (larger ones would step over the volume).
constexpr double kMinStepsPerVoxel = 16;
constexpr double kMaxSamplesPerCell = 64;
constexpr double kMaxSamplesPerRay = double(1 << 20);
/// The march frame (Engine::render) keeps each axis at least 2^-kMaxAxisRatioLog2 of the box's
/// longest extent: a thinner axis (spacing 1e-40 next to 1) is drawn that thin, so the float
/// world-to-index matrix stays finite (float cannot tell the two apart at the box's scale).
constexpr int kMaxAxisRatioLog2 = 40;

/// Sub-brick masks (Classification.h, subBrickMask): parts per brick edge, and the bricks that
/// have them (4 parts of >= 2 cells a side).
constexpr int kSubPerAxis = 4;
SS_FUNC bool usesSubMasks(int brick) { return brick >= 8 && brick % kSubPerAxis == 0; }
/// In a brick's state byte and in DistanceGrid's field: walk this occupied brick part by part
/// (Classification.h, subBrickState).
constexpr uint8_t kBrickPartsBit = 0x80;

struct BuildStats {
  BuilderKind builder = BuilderKind::Naive;
  std::string builtOn;       ///< "cpu" or "cuda"
  double seconds = 0;        ///< hierarchy construction
  double classifySeconds = 0;
  double classifyWaitSeconds = 0;  ///< of classifySeconds, the host's wait for the device (CUDA)
  int64_t nodes = 0;
  int height = 0;
  int64_t leaves = 0;
  double occupancy = 0;      ///< fraction of occupied macro cells
  /// Set sub-brick parts over all parts of the occupied bricks (Classification.h); 1: no masks.
  double partsShare = 1;
  /// Builder Auto: what it chose and why, one line ("" for the other builders, "exploring ..."
  /// while it measures).
  std::string choice;
};

/// Where the voxels live (sparse residency, BrickPool.h): in core, or only the pool bricks a
/// frame needs, in a pool of a device-memory budget.
struct ResidencyStats {
  bool sparse = false;        ///< false: the whole volume is resident (in core)
  int poolBrick = 0;          ///< cells per pool brick edge
  int64_t bricks = 0;         ///< pool bricks of the volume
  int64_t capacity = 0;       ///< pool slots allocated (grown with what views need)
  int64_t maxCapacity = 0;    ///< pool slots the budget allows
  int64_t needed = 0;         ///< pool bricks the last frame needed
  int64_t resident = 0;       ///< pool bricks resident after it
  int64_t uploaded = 0;       ///< pool bricks the last frame uploaded
  int64_t evicted = 0;        ///< pool bricks the last frame evicted
  double updateSeconds = 0;   ///< the last frame's residency update (needed set, gather, copies)
  int64_t budgetBytes = 0;    ///< the budget the choice was made against
  int64_t poolBytes = 0;      ///< bytes of the pool (slots x slot size)
  /// The last frame needed more bricks than the pool holds (the CPU backend then sampled the
  /// volume in host memory; the CUDA backend falls back to the CPU backend).
  bool overflow = false;
};

struct FrameStats {
  double seconds = 0;
  int64_t samples = -1;  ///< samples taken in the frame (RenderParams::countSamples), else -1
  double deviceSeconds = -1;  ///< render kernel time on the GPU (CUDA events), -1 on the CPU
  /// Scattering on the GPU: shadow rays the frame queued for its second pass (Tuning::deferShadows).
  int64_t queuedShadowRays = 0;
  /// CUDA, Tuning::heaviestFirst: the longest block (a tile's ray segment) of the frame before,
  /// by the SM clock, in seconds (-1: not measured). With the slowest blocks started first, a
  /// frame is longer than this only by what its other blocks add.
  double longestBlockSeconds = -1;
  std::string backend;
  ResidencyStats residency;
};

/// How often each stage ran: what tests use to check "rebuild only what a change needs".
struct Counters {
  int rangeGrids = 0;
  int classifications = 0;
  int builds = 0;
  /// Frames Builder Auto drew with the structure built before an edit that only emptied bricks
  /// (Backend::lastClassifyOnlyEmptied), leaving its rebuild to the next frame.
  int staleFrames = 0;
  int colorUpdates = 0;
  int frames = 0;
  /// Measurings Builder Auto ran on probes (BuildParams::autoProbe), each inside one frame.
  int autoProbeMeasurings = 0;
  /// Probe frames drawn for them (not counted in `frames`).
  int autoProbeFrames = 0;
  /// Whole-table compares of Engine::setTransferFunction (the parts its caller said may differ).
  int colorCompares = 0, opacityCompares = 0;
  /// Passes over the voxels: value ranges, label sets (labelSets) and the CPU backend's
  /// sub-brick masks after a classification. A label table edit makes none.
  int voxelPasses = 0;
  /// Label maps: per-brick label sets computed (once per volume and brick size).
  int labelSets = 0;
  /// Engine::setVolume calls that were a time step: a volume of the same shape (dims, type,
  /// components, spacing, origin, direction) as the one before, whose Builder Auto choice is kept
  /// (the kept structure is rebuilt for the step as after an opacity edit; Auto measures again
  /// only when the occupancy moved by more than AutoBuilder::kReexplore).
  int timeSteps = 0;
  /// Of those, steps whose voxels were already on the device (Engine::prefetchVolume).
  int prefetchedSteps = 0;
};

/// Host-to-device copy rates (bytes per second; 0 where there is no device), measured by
/// Engine::measureUpload: a pinned buffer's copy (what the link can take), a pageable buffer's
/// plain cudaMemcpy, and the backend's own upload of a pageable buffer (HostStaging).
struct UploadRates {
  double pinned = 0, pageable = 0, staged = 0;
};

struct Image {
  int width = 0, height = 0;
  std::vector<vec4f> rgba;  ///< premultiplied, row 0 at the bottom
};

/// Raised for errors the caller can fall back from (no CUDA device, device out of memory).
struct BackendError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws std::invalid_argument for parameters no builder accepts (bins 1 or negative, an unknown
/// builder): the one place they are checked (Builders.cpp).
void validate(const BuildParams& p);

}  // namespace spaceskip
