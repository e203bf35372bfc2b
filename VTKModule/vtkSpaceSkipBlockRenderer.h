// vtkSpaceSkipBlockRenderer: composite input (vtkMultiBlockDataSet, vtkPartitionedDataSet,
// vtkPartitionedDataSetCollection of vtkImageData) for vtkSpaceSkippingVolumeMapper.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipBlockRenderer_h
#define vtkSpaceSkipBlockRenderer_h

#include "vtkSmartPointer.h"              // For the block mappers
#include "vtkSpaceSkippingVolumeMapper.h" // For the statistics getters

#include <algorithm>  // For std::max

#include <functional> // For WarnFunction
#include <memory>     // For the compositor
#include <string>     // For the warning texts
#include <vector>     // For the blocks

class vtkDataObject;
class vtkImageData;
class vtkSpaceSkipCompositor;
namespace spaceskip
{
struct Image;
}
class vtkRenderer;
class vtkVolume;
class vtkWindow;

/**
 * Draws every vtkImageData leaf of a composite data set with a mapper of its own (its own
 * engine and hierarchy), as vtkMultiBlockVolumeMapper does with its vtkSmartVolumeMapper per
 * block, but as one image would be drawn:
 * - **one sample lattice**: when the blocks lie on one voxel lattice (same spacing and
 *   orientation, origins a whole number of voxels apart), each block is a piece of the image
 *   they make together (spaceskip::VolumePiece, as an MPI rank's piece): its rays take the
 *   whole image's samples and it draws only its own cells. Blocks that share a face of points
 *   own the cells on their side; between blocks that do not (a gap of one cell), the lower
 *   block owns the gap and gets the neighbours' voxels it reads (a padded copy); with shading
 *   (or slice mode) one more layer for the gradients. Cells marked duplicate in a block's
 *   ghost array are left to their owner. Blocks off one lattice (different spacing,
 *   orientation, a fractional offset) or overlapping: one warning, each block sampled on its
 *   own from its box entry (seams at the faces possible).
 * - **float compositing**: every block renders into its float image; the images are blended
 *   front to back per pixel in visibility order (a binary space partition of the owned boxes by
 *   axis planes, exact for grid and k-d splits; else by the distance of the block centres), and
 *   the sum reaches the window once, rounded once.
 * All blocks sample the transfer function over the same table range (the union of the blocks'
 * scalar ranges). Other leaves (rectilinear grids, unstructured data) are skipped with one
 * warning.
 */
class vtkSpaceSkipBlockRenderer
{
public:
  vtkSpaceSkipBlockRenderer();
  ~vtkSpaceSkipBlockRenderer();

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

  ///@{
  /// MPI with a piece exchange: while `pieces` is set, Render() on the whole image's lattice
  /// leaves each block's image there (cropped, with its cells in the lattice's index space)
  /// instead of drawing the blocks; ExchangeCamera() gives the camera in that index space and
  /// DrawSum() draws this frame's blended blocks (Render() itself, or after all when the
  /// exchange is off); false when it cannot draw.
  void SetExchangePieces(std::vector<vtkSpaceSkippingVolumeMapper::PieceImage>* pieces)
  {
    this->ExchangePieces = pieces;
  }
  void ExchangeCamera(vtkRenderer* ren, vtkVolume* vol, double eye[3], double dir[3], bool& parallel) const;
  bool DrawSum(vtkRenderer* ren, bool eightBit);
  ///@}

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
  /// How the blended blocks reached the window: "host", or "none" before the first draw.
  const char* GetCompositePath() const;
  /// The smallest sample distance the blocks used.
  double MinSampleDistance() const;
  /// Frames drawn through the blocks (one per Render() that drew at least one block).
  int GetFrameCount() const { return this->Frames; }
  ///@}

private:
  struct Block
  {
    vtkSmartPointer<vtkSpaceSkippingVolumeMapper> Mapper;
    vtkImageData* Image = nullptr;
    // On the shared lattice: the block in the first block's index space (the leaf's arrays, or
    // a copy padded with its neighbours' voxels), and the cells it draws, [lo, hi) per axis.
    vtkSmartPointer<vtkImageData> Piece;
    int Owned[6] = { 0, 0, 0, 0, 0, 0 };
    bool Padded = false; // Piece is a copy holding the drawn scalars alone
    bool Draws = true;  // false: every cell is another block's (all ghost), or no scalars
    double Depth = 0;   // distance of the block's centre from the camera (the sort off-lattice)
  };
  // Lays the blocks on one lattice (Piece, Owned, WholeExtent); false with the reason when they
  // are not on one.
  bool PlanLattice(vtkSpaceSkippingVolumeMapper* parent, int layers, std::string& why);
  // MPI (WholeExtent given): raises the summed colour by `bias` where a pixel's ray goes on
  // into another rank's blocks behind this rank's (IceT's 8-bit blend truncates).
  void AddFollowBias(vtkRenderer* ren, vtkVolume* vol, float bias);
  // Front-to-back order of the drawn blocks (indices into Blocks).
  std::vector<size_t> VisibilityOrder(vtkRenderer* ren, vtkVolume* vol) const;

  std::vector<Block> Blocks;
  bool Active = false;
  int Frames = 0;
  std::string NamesText;
  // The lattice of the last plan and what it was made from (re-planned when that changes).
  bool OnLattice = false;
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<unsigned long long> PlanKey;
  std::string OffLatticeWhy;
  vtkSmartPointer<vtkImageData> Lattice; // the lattice's geometry (origin, spacing, orientation)
  std::unique_ptr<vtkSpaceSkipCompositor> Compositor; // draws the blended blocks
  std::unique_ptr<spaceskip::Image> SumImage;          // the blended blocks, row 0 at the bottom
  std::vector<float> Alpha;                            // SumImage's opacity, for the next block
  std::vector<vtkSpaceSkippingVolumeMapper::PieceImage>* ExchangePieces = nullptr;
};

#endif
