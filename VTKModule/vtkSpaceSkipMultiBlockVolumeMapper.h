/**
 * @class   vtkSpaceSkipMultiBlockVolumeMapper
 * @brief   Composite input (vtkMultiBlockDataSet, vtkPartitionedDataSet,
 *          vtkPartitionedDataSetCollection of vtkImageData) for vtkSpaceSkippingVolumeMapper.
 *
 * Draws every vtkImageData leaf with a mapper of its own (its own engine and hierarchy), as
 * vtkMultiBlockVolumeMapper does with a vtkSmartVolumeMapper per block, but as one image would be
 * drawn:
 * - **one sample lattice**: when the blocks lie on one voxel lattice (spaceskip::planLattice),
 *   each block is a piece of the image they make together (spaceskip::VolumePiece, as an MPI
 *   rank's piece): its rays take the whole image's samples and it draws only its own cells.
 *   Blocks off one lattice (different spacing, orientation, a fractional offset) or overlapping:
 *   one warning, each block sampled on its own from its box entry (seams at the faces possible).
 * - **float compositing**: every block renders into its float image; the images are blended
 *   front to back per pixel in visibility order (spaceskip::visibilityOrder of the owned boxes;
 *   else by the distance of the block centres), and the sum reaches the window once.
 * All blocks sample the transfer function over the same table range (the union of the blocks'
 * scalar ranges). Other leaves are skipped with one warning.
 *
 * The mappers of the blocks are vtkSpaceSkippingVolumeMapper's, reached through BlockMapper
 * (made by the factory the owner sets), so that this class does not depend on the mapper that
 * owns it. Internal to the module (not wrapped, not installed).
 */
#ifndef vtkSpaceSkipMultiBlockVolumeMapper_h
#define vtkSpaceSkipMultiBlockVolumeMapper_h

#include "vtkSmartPointer.h" // For the lattice
#include "vtkVolumeMapper.h"

#include "vtkSpaceSkipInputConverter.h" // For vtkSpaceSkipRectilinearImage
#include "vtkSpaceSkipPieceExchange.h" // For vtkSpaceSkipPieceImage
#include "vtkSpaceSkipSettings.h"      // For the settings
#include "vtkSpaceSkipStatistics.h"    // For the statistics

#include <functional> // For BlockFactory, WarnFunction
#include <map>        // For the rectilinear leaves
#include <memory>     // For the block mappers
#include <string>     // For the problem
#include <vector>     // For the blocks

class vtkDataArray;
class vtkDataObject;
class vtkImageData;
class vtkRectilinearGrid;
class vtkSpaceSkipCompositor;
namespace spaceskip
{
struct Image;
struct LatticePlan;
}

class vtkSpaceSkipMultiBlockVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkSpaceSkipMultiBlockVolumeMapper* New();
  vtkTypeMacro(vtkSpaceSkipMultiBlockVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The mapper of one image block, as this class drives it.
  class BlockMapper
  {
  public:
    virtual ~BlockMapper() = default;
    virtual void SetInput(vtkImageData* image) = 0;
    /**
     * The owner's settings (`padded`: the input is a copy holding the drawn scalars alone, as
     * its active point scalars), the transfer function's table range, and on one lattice the
     * whole image's extent and the cells the block draws ([lo, hi) per axis; null: its own box).
     */
    virtual void Configure(const vtkSpaceSkipSettings& settings, bool padded,
      const double tableRange[2], const int* wholeExtent, const int* owned) = 0;
    /// Renders the block into its float image (premultiplied RGBA, row 0 at the bottom), each
    /// ray going on with `incomingAlpha` (null: none); null when it drew nothing.
    virtual const float* Render(vtkRenderer* ren, vtkVolume* vol, const float* incomingAlpha,
      int& width, int& height) = 0;
    virtual vtkSpaceSkipStatistics GetStatistics(bool deviceTimes) = 0;
    virtual void ReleaseGraphicsResources(vtkWindow* win) = 0;
  };
  using BlockFactory = std::function<std::unique_ptr<BlockMapper>()>;
  using WarnFunction = std::function<void(const std::string&)>;

  ///@{
  /// Set by the owner: how a block mapper is made, its settings, and where warnings go.
  void SetBlockFactory(const BlockFactory& factory) { this->Factory = factory; }
  void SetSettings(const vtkSpaceSkipSettings& settings) { this->Settings = settings; }
  void SetWarnFunction(const WarnFunction& warn) { this->Warn = warn; }
  ///@}

  /// Draws the image leaves of the input through one block mapper each.
  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  /// Why the last Render() drew nothing (no image block with the selected scalars), or empty.
  const std::string& GetLastProblem() const { return this->Problem; }

  void ReleaseGraphicsResources(vtkWindow* win) override;

  /// Statistics of the last frame, the blocks' combined (vtkSpaceSkipStatistics::Combine).
  vtkSpaceSkipStatistics GetStatistics(bool deviceTimes);

  ///@{
  /// The first non-empty vtkImageData leaf of `input`, or null; the union of the bounds of the
  /// image leaves (false when there is none).
  static vtkImageData* FirstImage(vtkDataObject* input);
  static bool ComputeBounds(vtkDataObject* input, double bounds[6]);
  ///@}

  ///@{
  /// MPI with a piece exchange: while `pieces` is set, Render() on the whole image's lattice
  /// leaves each block's image there (cropped, with its cells in the lattice's index space)
  /// instead of drawing the blocks; ExchangeCamera() gives the camera in that index space and
  /// DrawSum() draws this frame's blended blocks (Render() itself, or after all when the
  /// exchange is off); false when it cannot draw.
  void SetExchangePieces(std::vector<vtkSpaceSkipPieceImage>* pieces) { this->Pieces = pieces; }
  void ExchangeCamera(vtkRenderer* ren, vtkVolume* vol, double eye[3], double dir[3], bool& parallel) const;
  bool DrawSum(vtkRenderer* ren, bool eightBit);
  ///@}

protected:
  vtkSpaceSkipMultiBlockVolumeMapper();
  ~vtkSpaceSkipMultiBlockVolumeMapper() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;

private:
  vtkSpaceSkipMultiBlockVolumeMapper(const vtkSpaceSkipMultiBlockVolumeMapper&) = delete;
  void operator=(const vtkSpaceSkipMultiBlockVolumeMapper&) = delete;

  struct Block
  {
    std::unique_ptr<BlockMapper> Mapper;
    vtkImageData* Image = nullptr;
    // On the shared lattice: the block in the lattice's index space (the leaf's arrays, or a
    // copy padded with its neighbours' voxels), and the cells it draws, [lo, hi) per axis.
    vtkSmartPointer<vtkImageData> Piece;
    int Owned[6] = { 0, 0, 0, 0, 0, 0 };
    bool Padded = false; // Piece is a copy holding the drawn scalars alone
    bool Draws = true;   // false: every cell is another block's (all ghost), or no scalars
    double Depth = 0;    // distance of the block's centre from the camera (the sort off-lattice)
  };
  // The image leaves (warning about the others); false when nothing is to be drawn.
  bool CollectImages(vtkRenderer* ren, std::vector<vtkImageData*>& images);
  // The table range every block uses; false (Problem set) when no block has the scalars.
  bool TableRange(const std::vector<vtkImageData*>& images, double range[2]);
  // A second array as the 2-D function's y axis: the blocks' range of it, unless one was given.
  void SecondAxisRange(const std::vector<vtkImageData*>& images);
  // Lays the blocks on one lattice when what it depends on changed (spaceskip::planLattice).
  void UpdateLattice(const std::vector<vtkImageData*>& images, vtkVolume* vol);
  // `second`: the blocks' 2-D y-axis arrays (empty, or with a null: not padded).
  void ApplyPlan(const spaceskip::LatticePlan& plan, const std::vector<vtkDataArray*>& arrays,
    const std::vector<vtkDataArray*>& second);
  // Each block's settings, input and depth for this frame.
  void ConfigureBlocks(const double range[2], vtkRenderer* ren, vtkVolume* vol);
  // Whether this frame's block images go to the piece exchange (MPI, one lattice).
  bool ExchangesPieces() const;
  // Whether each block's rays go on with the opacity of the blocks in front.
  bool CarriesOpacity() const;
  // Every block into the float sum, front to back; false when none drew.
  bool RenderBlocks(vtkRenderer* ren, vtkVolume* vol, int width, int height);
  // MPI (WholeExtent given): raises the summed colour by `bias` where a pixel's ray goes on
  // into another rank's blocks behind this rank's (IceT's 8-bit blend truncates).
  void AddFollowBias(vtkRenderer* ren, vtkVolume* vol, float bias);
  // Front-to-back order of the drawn blocks (indices into Blocks).
  std::vector<size_t> VisibilityOrder(vtkRenderer* ren, vtkVolume* vol) const;

  BlockFactory Factory;
  vtkSpaceSkipSettings Settings;
  WarnFunction Warn;
  std::string Problem;
  std::vector<Block> Blocks;
  // The rectilinear leaves as images (vtkSpaceSkipInputConverter.h), by leaf.
  std::map<vtkRectilinearGrid*, vtkSpaceSkipRectilinearImage> Grids;
  int Frames = 0;
  // The lattice of the last plan and what it was made from (re-planned when that changes).
  bool OnLattice = false;
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<unsigned long long> PlanKey;
  std::string OffLatticeWhy;
  vtkSmartPointer<vtkImageData> Lattice; // the lattice's geometry (origin, spacing, orientation)
  std::unique_ptr<vtkSpaceSkipCompositor> Compositor; // draws the blended blocks
  std::unique_ptr<spaceskip::Image> SumImage;          // the blended blocks, row 0 at the bottom
  std::vector<float> Alpha;                            // SumImage's opacity, for the next block
  std::vector<vtkSpaceSkipPieceImage>* Pieces = nullptr;
};

#endif
