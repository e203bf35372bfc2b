// What both executors read per frame: plain data only (no virtuals, no STL), host pointers on
// the oneTBB backend and device pointers on CUDA, filled once per frame by the backend.
#pragma once
#include "../CropClip.h"
#include "../Math.h"
#include "../TransferFunction.h"
#include "../Tree.h"
#include "../Types.h"

#include <cstdint>

namespace spaceskip {

/// Occupancy grid as the integrator sees it (device pointer on the GPU).
struct GridView {
  const uint8_t* occ;
  vec3i dims;  ///< bricks per axis
  int brick;   ///< cells per brick edge
  /// Optional (DistanceGrid): per brick 0 when occupied, else the Chebyshev distance in bricks
  /// to the nearest occupied brick (DistanceField.h). When set, `occ` is not read.
  const uint8_t* dist = nullptr;
  /// Optional (value-range skipping, the MIP/MinIP/average/isosurface blend modes): per-brick
  /// min/max of the voxels a sample inside can interpolate (RangeGrid, +1 halo). When set,
  /// neither `occ` nor `dist` is read: a brick is visited when `visit.active(vmin, vmax)` says
  /// its samples can still change the ray's result, which depends on what the ray has seen so
  /// far; so every visited brick is handed over on its own, before the next one is decided.
  const float* vmin = nullptr;
  const float* vmax = nullptr;
  /// Optional (Grid, DistanceGrid): per brick its sub-brick mask (Classification.h,
  /// subBrickMask), read for occupied bricks whose byte (`occ`: the brick states, or `dist`)
  /// has kBrickPartsBit: the DDA then walks the brick's 4^3 parts and yields the set ones. Not
  /// read with value ranges.
  const uint64_t* sub = nullptr;
};

struct TreeView {
  const Node* nodes;
  int numNodes;
};

/// A volume rendered in pieces (one per MPI rank): the rays, the box, the planes and the sample
/// lattice are those of the whole volume (FrameView::worldToIndex maps to the whole volume's
/// index space; RayGen.h), so every piece samples where the serial render would; a piece draws
/// the samples in its owned cells only, half-open, so a sample on a shared face is drawn once.
/// The piece's own voxels, grid and tree are indexed from `pieceLo`. Inactive (serial): the
/// piece is the whole volume and nothing here is read.
struct LatticeView {
  int active = 0;
  vec3f pieceLo{0, 0, 0};  ///< the piece's voxel (0,0,0) in whole-volume indices (integers)
  vec3f ownLo{0, 0, 0};    ///< the cells the piece draws, [ownLo, ownHi), whole-volume indices
  vec3f ownHi{0, 0, 0};
  float followBias = 0.f;  ///< added to the colour where a piece lies behind (VolumePiece)
};

/// Most iso values the isosurface blend mode takes (they travel in the FrameView).
constexpr int kMaxIsoValues = 16;
/// Most samples a GPU march fetches before compositing the first of them (FrameView::sampleBatch).
constexpr int kMaxSampleBatch = 4;

/// A light of the light list (RenderParams::lights) in the frame's origin-relative world space.
struct LightView {
  vec3f dir;       ///< unit direction the light travels (position -> focal point); spot axis
  vec3f pos;       ///< positional: position
  vec3f diffuse;   ///< colour * intensity
  vec3f specular;  ///< colour * intensity
  vec3f atten;     ///< positional: constant, linear, quadratic attenuation
  float cosCone;   ///< positional: cos(cone angle) when a spot (cone <= 90 degrees), else -2
  float exponent;  ///< positional spot: falloff exponent
  int positional;
};

/// A positional light at world point pw (origin-relative): its direction of travel `ld` (unit;
/// the light's axis where pw is the light's position) and attenuation `att` (distance, then the
/// spot cone's falloff), as vtkGPUVolumeRayCastMapper computes them. The scalar integrator
/// (IntervalMarcher::shadeLights) and the CPU ray packets (CpuMarch.cpp, lane by lane) both
/// call it, so that their images agree bit for bit.
SS_FUNC void positionalLight(const LightView& L, vec3f pw, vec3f& ld, float& att) {
  const vec3f d = pw - L.pos;
  const float dist = length(d);
  ld = dist > 0.f ? d * (1.f / dist) : L.dir;
  att = 1.f / (L.atten.x + L.atten.y * dist + L.atten.z * dist * dist);
  if (L.cosCone > -2.f) {
    const float coneDot = dot(ld, L.dir);
    att = coneDot >= L.cosCone ? att * powf(coneDot, L.exponent) : 0.f;
  }
}

/// A 2-D transfer function or gradient opacity (TransferFunction::table2D / gradientOpacity) as
/// the integrator reads it (render/GradientTF.h): their entries follow the 1-D table in the
/// table the backend uploads (FrameView::tf.table + offset). Composite; one component, or for
/// mode 3 two (the table's x and y values: vtkGPUVolumeRayCastMapper's Transfer2DYAxisArray).
struct GradientTFView {
  int mode = 0;  ///< 0: none; 1: gradient opacity; 2: 2-D table at (value, gradient); 3: at (component 0, 1)
  int offset = 0;          ///< first entry in tf.table
  int width = 0, height = 0;  ///< 2-D: columns, rows; gradient opacity: entries (width)
  float xLo = 0.f, xScale = 0.f;  ///< 2-D: column position (v - xLo) * xScale - 1/2
  float yLo = 0.f, yScale = 0.f;  ///< mode 3: row position (component 1 - yLo) * yScale - 1/2
  /// Per index axis: the factor taking the central difference f(p+e) - f(p-e) to VTK's
  /// normalised gradient component, avgSpacing / (2 spacing) / (range / 4).
  float gradScale[3] = {0.f, 0.f, 0.f};
};

/// A shadow ray left for later (ScatterView::queue, render/Scattering.h scatterShade): its
/// start p (index space), its light (towards it in texture units, distance or INFINITY), its
/// step L and cutoff scale `weight` as shadowTransmittance takes them, and the colour it adds to
/// pixel `pixel` (row-major) at transmittance 1, the pixel's composite weight included.
struct ShadowRecord {
  vec3f p, towardT;
  float distT, L, weight;
  vec3f rgb;
  int pixel;
};

/// Volumetric shadows and scattering as vtkGPUVolumeRayCastMapper (VTK 9.2) draws them with
/// VolumetricScatteringBlending > 0, GlobalIlluminationReach and the volume property's
/// ScatteringAnisotropy (render/Scattering.h). Shadow rays live in VTK's texture space: texture
/// coordinate (i + 1/2) / n per axis (n points), the box [0, 1]^3; lights and the view direction
/// in its unadjusted form i / (n - 1). Composite and isosurface blending, shaded frames only.
struct ScatterView {
  int on = 0;
  float blending = 0.f;         ///< VolumetricScatteringBlending, (0, 2]
  float g = 0.f;                ///< Henyey-Greenstein anisotropy; |g| < 0.01: isotropic (phase 1)
  float reach = 0.f;            ///< the longest shadow ray in texture units (VTK's in_giReach)
  vec3f texN{1, 1, 1};          ///< points per axis n: texture units -> index units
  vec3f dirScale{1, 1, 1};      ///< 1 / (n - 1) per axis: index -> unadjusted texture units
  float gradScale[3] = {0.f, 0.f, 0.f};  ///< central difference -> VTK's gradient (normalised scalar per world length)
  float cutoff = 0.f;           ///< a shadow ray stops once its light's largest contribution falls below this
  /// Where each light is in unadjusted texture units (the headlight model: [0]): the direction
  /// towards it for a directional light, its position for a positional one.
  vec3f lightU[kMaxLights];
  int headPositional = 1;       ///< the headlight model: 1: a point light at the eye; 0: directional
  vec3f eyeIdx{0, 0, 0};        ///< the eye in index space (the view direction of the phase function)
  /// The brick occupancy the shadow rays skip with (every builder's classification, no cuts:
  /// VTK's shadow rays ignore cropping and clipping), with the sub-brick masks (brick states
  /// in occ, masks in sub) and DistanceGrid's field (dist) where there are; occ == nullptr:
  /// every sample is taken.
  GridView occ{};
  /// The CUDA executor's shadow queue (nullptr: every shadow ray is marched where its sample
  /// is): up to queueCapacity records; *queueCount counts the rays offered, those beyond the
  /// capacity included (they were marched in place), so that the next frame can size it.
  ShadowRecord* queue = nullptr;
  unsigned* queueCount = nullptr;
  unsigned queueCapacity = 0;
};

/// Everything a pixel needs, plain data (device pointers on the GPU).
struct FrameView {
  float invViewProj[16];   ///< NDC -> world, column-major
  float worldToIndex[12];  ///< world -> index space, row-major 3x4 affine
  int width, height;
  vec3f boxHi;             ///< index-space volume box is [0, boxHi) (the whole volume's: lattice)
  float dt;                ///< sample distance in world units
  float ertThreshold;      ///< early ray termination when alpha >= this; > 1 disables
  int jitter;              ///< 1: per-pixel random start offset in [0, dt)
  float firstSample;       ///< first sample at the box entry + firstSample * dt (see RenderParams)
  uint32_t jitterSeed;
  const float* depth;      ///< optional window depth in [0,1] per pixel (opaque geometry)
  /// Optional opacity each pixel's ray brings from the pieces in front of this one (pieces
  /// composited front to back in one process; composite and isosurface modes): the march goes
  /// on from it and the pixel returns the piece's own share (Engine::render).
  const float* alphaIn;
  TraversalKind traversal;
  GridView grid;           ///< Grid and Hybrid
  TreeView tree;           ///< Tree and Hybrid
  TransferFunctionView tf;
  unsigned* sampleCount;   ///< optional per-pixel count of samples taken (statistics)
  CropClip cut;            ///< clipping and cropping planes: the ones classification used
  // Blend mode and shading (vtkVolumeMapper / vtkVolumeProperty semantics).
  BlendMode blend;
  float normLo, normScale;  ///< additive/average: normalised scalar = (v - normLo) * normScale
  float avgLo, avgHi;       ///< average: only samples with value in [avgLo, avgHi] count
  int numIso;               ///< isosurface: iso values, ascending
  float iso[kMaxIsoValues];
  int shade;                ///< 1: gradient shading (composite and isosurface, as VTK)
  float ambient, diffuse, specular, specularPower;
  vec3f lightDir;           ///< world direction towards the light; (0,0,0): headlight
  vec3f eyeW;               ///< camera position in world space (the headlight; parallel views too)
  // Lights (shading): 1: VTK's light-list model over lights[0, numLights) (0 lights: black);
  // 0: the headlight model with lightDir.
  int useLights;
  int numLights;
  int twoSided;             ///< two-sided lighting (vtkRenderer's TwoSidedLighting)
  vec3f lightAmbient;       ///< sum of the lights' ambient colours * intensities
  LightView lights[kMaxLights];
  float slicePlane[4];      ///< slice blend mode: the index-space plane s.p + s[3] = 0
  int sliceAsVTK;           ///< slice: sample where vtkGPUVolumeRayCastMapper does (RenderParams)
  LatticeView lattice;      ///< rendering one piece of a larger volume (MPI); inactive: serial
  // Dependent components (Volume::components 2 or 4; render/Components.h). Unused with 1.
  float alphaLo, alphaScale;    ///< opacity channel -> table entry: (v - alphaLo) * alphaScale
  float rgbLo[3], rgbScale[3];  ///< 4 components: colour c = clamp((v_c - rgbLo[c]) * rgbScale[c], 0, 1)
  int gradientComponent;        ///< shading: the component whose gradient lights a sample
  /// Samples of a run fetched together before any is composited in plain frames, with samplers
  /// that ask for it (IntervalMarcher::takeBatch, SamplerBatch): 1..kMaxSampleBatch; <= 1: one
  /// at a time. The CUDA executor sets it (the host's cores overlap the fetches of a loop on
  /// their own); the image is the same either way.
  int sampleBatch;
  GradientTFView gtf;  ///< 2-D transfer function / gradient opacity (mode 0: neither)
  /// How voxels are sampled (render/LabelSampler.h): 0 trilinear (the default); 1 the nearest
  /// voxel's value; 2, 3 a label map, its nearest label or the argmax of the corners' label
  /// weights, drawn through labelLookup. One-component volumes; the executors pick the sampler.
  int sampling;
  ScatterView scatter;  ///< volumetric shadows and scattering (off: on == 0)
};

}  // namespace spaceskip
