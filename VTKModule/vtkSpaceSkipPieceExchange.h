// vtkSpaceSkipPieceExchange: float compositing of the pieces of several processes (ParaView's
// ranks under MPI), the interface vtkSpaceSkippingVolumeMapper::SetPieceExchange takes
// (vtkSpaceSkippingVolumeMapper::PieceImage and ::PieceExchange name these types).
#ifndef vtkSpaceSkipPieceExchange_h
#define vtkSpaceSkipPieceExchange_h

#ifndef __VTK_WRAP__
#include <vector> // For the pixels and the pieces

/// A process's piece image: the rectangle of pixels it drew (premultiplied RGBA floats, rows
/// bottom up, at X, Y in the viewport) and the cells it drew, [lo, hi) per axis in the index
/// space of the mapper's WholeExtent (lo == hi: none). Its pixels lie in host memory (Pixels), in
/// this process's device memory (Device: Width x Height float4, row after row, written on the
/// cudaStream_t Stream), or in another process's device memory on the same host (Shared: Handle
/// names it, a cudaIpcMemHandle_t; the mapper maps it under Source, the rank that drew it).
struct vtkSpaceSkipPieceImage
{
  int Owned[6] = { 0, 0, 0, 0, 0, 0 };
  int X = 0, Y = 0, Width = 0, Height = 0;
  std::vector<float> Pixels;
  const void* Device = nullptr;
  void* Stream = nullptr;
  int Source = 0;
  bool Shared = false;
  char Handle[64] = {};
};

/**
 * While one is set and the mapper's input is a piece of a larger image, every Render() calls
 * Begin(), renders the piece (or each block) exactly into a float image and hands them to
 * Finish(), whose answer says what this process draws.
 */
class vtkSpaceSkipPieceExchange
{
public:
  virtual ~vtkSpaceSkipPieceExchange() = default;
  /// At the start of Render(), before the piece is drawn.
  virtual void Begin() = 0;
  /**
   * Hands over this process's pieces (one for an image piece, one per block for partitioned
   * input) of a `width` x `height` viewport. Returns 1 with the other processes' pieces in
   * `others` (this process composites and draws them all), 0 (draw nothing here: another
   * process draws these pieces), or -1 (the exchange is off: draw them here, the 8-bit path).
   */
  virtual int Finish(int width, int height, std::vector<vtkSpaceSkipPieceImage>& mine,
    std::vector<vtkSpaceSkipPieceImage>& others) = 0;
  /**
   * How Finish() takes a piece the mapper left in device memory (a CUDA frame): 0, its pixels in
   * host memory; 1, shared (the mapper copies it into an image the other processes of the host
   * map through CUDA IPC, and sets Shared and Handle); 2, shared and in host memory too (until
   * the process that composites has mapped it once). Pieces Finish() hands back may be Shared.
   */
  virtual int DevicePieces() const { return 0; }
  /// After Finish() answered 1, once the pieces it handed back are read (blended): the other
  /// processes may draw their next frame over their shared images. `mapped` false: a shared
  /// piece could not be mapped (from then on the pieces travel through host memory).
  virtual void Released(bool mapped) { (void)mapped; }
};
#endif

#endif
