// vtkSpaceSkipBlockRenderer: composite input (vtkMultiBlockDataSet, vtkPartitionedDataSet,
// vtkPartitionedDataSetCollection of vtkImageData) for vtkSpaceSkippingVolumeMapper.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipBlockRenderer_h
#define vtkSpaceSkipBlockRenderer_h

#include "vtkSmartPointer.h"              // For the block mappers
#include "vtkSpaceSkippingVolumeMapper.h" // For the statistics getters

#include <algorithm>  // For std::max

#include <functional> // For WarnFunction
#include <string>     // For the warning texts
#include <vector>     // For the blocks

class vtkDataObject;
class vtkImageData;
class vtkRenderer;
class vtkVolume;
class vtkWindow;

/**
 * Draws every vtkImageData leaf of a composite data set with a mapper of its own (its own
 * engine and hierarchy), as vtkMultiBlockVolumeMapper does with its vtkSmartVolumeMapper per
 * block: the block mappers take the parent's settings, are sorted back to front by the distance
 * of their block's centre from the camera, and each blends its image over what the ones before
 * it drew. All blocks sample the transfer function over the same table range (the union of the
 * blocks' scalar ranges), so that adjacent blocks render as one image would. Other leaves
 * (rectilinear grids, unstructured data) are skipped with one warning.
 */
class vtkSpaceSkipBlockRenderer
{
public:
  using WarnFunction = std::function<void(const std::string&)>;

  /// Whether `input` is a composite data set (this class draws it).
  static bool IsComposite(vtkDataObject* input);

  /**
   * Draws the image leaves of `input` through one block mapper each; false, with `problem`
   * set, when it holds no image with the selected point scalars.
   */
  bool Render(vtkSpaceSkippingVolumeMapper* parent, vtkDataObject* input, vtkRenderer* ren,
    vtkVolume* vol, const WarnFunction& warnOnce, std::string& problem);

  /// The first non-empty vtkImageData leaf of `input`, or null.
  static vtkImageData* FirstImage(vtkDataObject* input);

  /// Union of the bounds of the image leaves of `input`; false when it holds none.
  static bool ComputeBounds(vtkDataObject* input, double bounds[6]);

  void ReleaseGraphicsResources(vtkWindow* win);

  /// Whether the last Render() drew blocks (the parent's statistics then add them up).
  bool IsActive() const { return this->Active; }
  /// Forgets the blocks (the input is no longer composite).
  void Clear();

  ///@{
  /// Statistics over the block mappers of the last frame (see vtkSpaceSkippingVolumeMapper):
  /// sums (times, node counts, stage counts) and maxima (tree height).
  template <typename T>
  T Sum(T (vtkSpaceSkippingVolumeMapper::*getter)()) const
  {
    T sum = 0;
    for (const Block& b : this->Blocks)
    {
      sum += ((*b.Mapper).*getter)();
    }
    return sum;
  }
  template <typename T>
  T Max(T (vtkSpaceSkippingVolumeMapper::*getter)()) const
  {
    T best = 0;
    for (const Block& b : this->Blocks)
    {
      best = std::max(best, ((*b.Mapper).*getter)());
    }
    return best;
  }
  /// Occupancy over all blocks, weighted by their voxel counts.
  double Occupancy() const;
  /// A string statistic of the blocks: the one value when all agree, else the values joined by '/'.
  const char* Names(const char* (vtkSpaceSkippingVolumeMapper::*getter)());
  /// The smallest sample distance the blocks used.
  double MinSampleDistance() const;
  /// Frames drawn through the blocks (one per Render() that drew at least one block).
  int GetFrameCount() const { return this->Frames; }
  int GetNumberOfBlocks() const { return static_cast<int>(this->Blocks.size()); }
  ///@}

private:
  struct Block
  {
    vtkSmartPointer<vtkSpaceSkippingVolumeMapper> Mapper;
    vtkImageData* Image = nullptr;
    double Depth = 0; // distance of the block's centre from the camera, for the sort
  };
  std::vector<Block> Blocks;
  bool Active = false;
  int Frames = 0;
  std::string NamesText;
};

#endif
