// vtkSpaceSkipStatistics: what a vtkSpaceSkippingVolumeMapper reports of its last build and frame
// (its getters read one of these), and the statistics of a composite input's blocks combined.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipStatistics_h
#define vtkSpaceSkipStatistics_h

#include "vtkIndent.h" // For Print
#include "vtkType.h"   // For vtkIdType

#include <ostream> // For Print
#include <string>  // For the names
#include <vector> // For Combine

struct vtkSpaceSkipStatistics
{
  // Seconds of the last build and frame (see the mapper's getters).
  double BuildSeconds = 0;
  double ClassifySeconds = 0;
  double RenderSeconds = 0; // with `deviceTimes` only (asking waits for the frame)
  double KernelSeconds = 0; // with `deviceTimes` only
  double ScalarRangeSeconds = 0;
  double UpdateSeconds = 0;
  double DepthReadSeconds = 0;
  double EngineRenderSeconds = 0;
  double CompositeSeconds = 0;
  double MapperSeconds = 0;
  bool DepthRead = false;
  int CompositeRect[4] = { 0, 0, 0, 0 };

  // The hierarchy and the frame.
  vtkIdType Nodes = 0;
  vtkIdType Leaves = 0;
  int TreeHeight = 0;
  double Occupancy = 0;
  double SampleDistanceUsed = 0;
  vtkIdType ResidentBricks = 0;
  std::string BackendUsed = "none";
  std::string BuilderUsed = "none";
  std::string BuilderChoice;
  std::string Residency = "none";
  std::string CompositePath = "none";
  std::string CompositeBlend = "none";
  std::string CudaDevice = "none"; // "device N of M" when the CUDA backend drew
  // How the processes' pieces met (a PieceExchange, e.g. MPI ranks): "none" without one.
  std::string PieceCompositing = "none";

  // How often each stage ran since the mapper was created.
  int Builds = 0;
  int Classifications = 0;
  int ColorUpdates = 0;
  int Frames = 0;
  int ColorTableSamples = 0;
  int OpacityTableSamples = 0;
  int TimeSteps = 0;           // volumes of the last one's shape (Engine counters' timeSteps)
  int PrefetchedTimeSteps = 0; // of those, found on the device (PrefetchTimeStep)

  /// The mapper's PrintSelf lines for what ran and the hierarchy.
  void Print(std::ostream& os, vtkIndent indent) const;

  /**
   * The blocks of a composite input as one: times, nodes, leaves, resident bricks and stage
   * counts add up, the tree height is the largest, the occupancy the mean weighted by `voxels`,
   * the sample distance the smallest, names one per distinct value joined by '/'.
   */
  static vtkSpaceSkipStatistics Combine(
    const std::vector<vtkSpaceSkipStatistics>& blocks, const std::vector<double>& voxels);
};

#endif
