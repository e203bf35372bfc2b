// vtkSpaceSkipStatistics: the statistics of a composite input's blocks combined.
#include "vtkSpaceSkipStatistics.h"

#include <algorithm>

namespace
{
// One value per distinct string, in first-seen order, joined by '/'.
std::string Join(const std::vector<vtkSpaceSkipStatistics>& blocks,
  std::string vtkSpaceSkipStatistics::*name)
{
  std::vector<std::string> seen;
  for (const vtkSpaceSkipStatistics& b : blocks)
  {
    if (std::find(seen.begin(), seen.end(), b.*name) == seen.end())
    {
      seen.push_back(b.*name);
    }
  }
  std::string joined;
  for (const std::string& s : seen)
  {
    joined += (joined.empty() ? "" : "/") + s;
  }
  return joined;
}
}

//------------------------------------------------------------------------------
vtkSpaceSkipStatistics vtkSpaceSkipStatistics::Combine(
  const std::vector<vtkSpaceSkipStatistics>& blocks, const std::vector<double>& voxels)
{
  vtkSpaceSkipStatistics s;
  double weighted = 0, total = 0;
  for (size_t i = 0; i < blocks.size(); ++i)
  {
    const vtkSpaceSkipStatistics& b = blocks[i];
    for (double vtkSpaceSkipStatistics::*t :
      { &vtkSpaceSkipStatistics::BuildSeconds, &vtkSpaceSkipStatistics::ClassifySeconds,
        &vtkSpaceSkipStatistics::RenderSeconds, &vtkSpaceSkipStatistics::KernelSeconds,
        &vtkSpaceSkipStatistics::ScalarRangeSeconds, &vtkSpaceSkipStatistics::UpdateSeconds,
        &vtkSpaceSkipStatistics::DepthReadSeconds, &vtkSpaceSkipStatistics::EngineRenderSeconds,
        &vtkSpaceSkipStatistics::CompositeSeconds })
    {
      s.*t += b.*t;
    }
    for (int vtkSpaceSkipStatistics::*c :
      { &vtkSpaceSkipStatistics::Builds, &vtkSpaceSkipStatistics::Classifications,
        &vtkSpaceSkipStatistics::ColorUpdates, &vtkSpaceSkipStatistics::Frames,
        &vtkSpaceSkipStatistics::ColorTableSamples, &vtkSpaceSkipStatistics::OpacityTableSamples,
        &vtkSpaceSkipStatistics::TimeSteps, &vtkSpaceSkipStatistics::PrefetchedTimeSteps })
    {
      s.*c += b.*c;
    }
    s.DepthRead = s.DepthRead || b.DepthRead;
    s.Nodes += b.Nodes;
    s.Leaves += b.Leaves;
    s.ResidentBricks += b.ResidentBricks;
    s.TreeHeight = std::max(s.TreeHeight, b.TreeHeight);
    const double n = i < voxels.size() ? voxels[i] : 0.0;
    weighted += n * b.Occupancy;
    total += n;
    if (b.SampleDistanceUsed > 0 && (s.SampleDistanceUsed == 0 || b.SampleDistanceUsed < s.SampleDistanceUsed))
    {
      s.SampleDistanceUsed = b.SampleDistanceUsed;
    }
  }
  s.Occupancy = total > 0 ? weighted / total : 0.0;
  s.BackendUsed = Join(blocks, &vtkSpaceSkipStatistics::BackendUsed);
  s.BuilderUsed = Join(blocks, &vtkSpaceSkipStatistics::BuilderUsed);
  s.BuilderChoice = Join(blocks, &vtkSpaceSkipStatistics::BuilderChoice);
  s.Residency = Join(blocks, &vtkSpaceSkipStatistics::Residency);
  s.CudaDevice = Join(blocks, &vtkSpaceSkipStatistics::CudaDevice);
  return s;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatistics::Print(std::ostream& os, vtkIndent indent) const
{
  os << indent << "CompositePathUsed: " << this->CompositePath << "\n";
  os << indent << "CompositeBlendUsed: " << this->CompositeBlend << "\n";
  os << indent << "BackendUsed: " << this->BackendUsed << "\n";
  os << indent << "CudaDeviceUsed: " << this->CudaDevice << "\n";
  os << indent << "PieceCompositingUsed: " << this->PieceCompositing << "\n";
  os << indent << "BuilderUsed: " << this->BuilderUsed << "\n";
  os << indent << "LastBuildSeconds: " << this->BuildSeconds << "\n";
  os << indent << "LastRenderSeconds: " << this->RenderSeconds << "\n";
  os << indent << "NodeCount: " << this->Nodes << "\n";
  os << indent << "TreeHeight: " << this->TreeHeight << "\n";
  os << indent << "LeafCount: " << this->Leaves << "\n";
  os << indent << "BuildCount: " << this->Builds << "\n";
  os << indent << "ClassifyCount: " << this->Classifications << "\n";
  os << indent << "ColorUpdateCount: " << this->ColorUpdates << "\n";
  os << indent << "TimeStepCount: " << this->TimeSteps << " (prefetched " << this->PrefetchedTimeSteps
     << ")\n";
}
