// vtkSpaceSkipMPIExchange: float compositing of the ranks' pieces for vtkSpaceSkippingVolumeMapper
// under MPI (its PieceExchange). Internal to the representation module.
#ifndef vtkSpaceSkipMPIExchange_h
#define vtkSpaceSkipMPIExchange_h

#include "vtkSmartPointer.h"
#include "vtkSpaceSkippingVolumeMapper.h"

#include <chrono>
#include <functional>
#include <list>
#include <memory>
#include <string>
#include <vector>

class vtkMPIController;
class vtkMultiProcessController;

/**
 * Every rank draws its piece exactly into a float image; rank 0 receives the others' images (the
 * rectangle of pixels they drew, and their cells), its mapper blends all of them front to back in
 * the order the rays meet the pieces and draws the sum; the other ranks draw nothing. IceT then
 * composites one exact image with empty ones, which its 8-bit blend leaves unchanged: N ranks
 * give the serial image (within one rounding).
 *
 * On one host (`oneHost`) a CUDA frame stays on its GPU: each rank copies it into an image the
 * others map through CUDA IPC and sends only its handle; rank 0's mapper blends the pieces on its
 * GPU, reading the others' memory where it lies (NVLink or PCIe), and draws the sum through
 * CUDA-GL interop. Until rank 0 has mapped a rank's image once, that rank sends its pixels too;
 * a failure to map turns it off (host memory from then on, said once). Rank 0 sends the verdict
 * only after the blend (Released), so no rank draws over an image still being read.
 *
 * It never waits forever. The messages travel on a communicator of its own. Other ranks send
 * without waiting (non-blocking sends). Rank 0 waits for every rank's "frame begun" message for
 * at most `BeginSeconds` after its own Begin() (ParaView's IceT draws every rank in the same
 * frame: the representation asks for RENDER_EMPTY_IMAGES, the mapper reports the whole image's
 * bounds), then for the images of the ranks that began (they are drawing). At its end it sends
 * each rank a verdict; a rank waits for the previous frame's verdict at most `BeginSeconds`.
 * When a rank is missing, late or on another frame, the exchange gives up on every rank, with
 * one message, and the ranks draw their own pieces again (ParaView's 8-bit compositing).
 */
class vtkSpaceSkipMPIExchange : public vtkSpaceSkippingVolumeMapper::PieceExchange
{
public:
  using WarnFunction = std::function<void(const std::string&)>;

  /// Collective over `controller`'s ranks (it duplicates the communicator); null when
  /// `controller` is not an MPI controller of more than one rank.
  /// `oneHost`: every rank runs on one host (their GPUs may map each other's frames: the pieces
  /// then stay on the GPUs, DevicePieces()).
  static std::shared_ptr<vtkSpaceSkipMPIExchange> New(
    vtkMultiProcessController* controller, WarnFunction warn, bool oneHost = false);
  ~vtkSpaceSkipMPIExchange() override;

  /**
   * This rank's number among the ranks of its node (those that share memory with it:
   * MPI_Comm_split_type with MPI_COMM_TYPE_SHARED) and how many they are; one rank per GPU binds
   * CUDA device `local` (modulo the devices). Collective over `controller`'s ranks; false (0 of
   * 1) when it is not an MPI controller or MPI fails.
   */
  static bool NodeLocalRank(vtkMultiProcessController* controller, int& local, int& ranksOnNode);

  using PieceImage = vtkSpaceSkippingVolumeMapper::PieceImage;
  void Begin() override;
  int Finish(int width, int height, std::vector<PieceImage>& mine,
    std::vector<PieceImage>& others) override;
  int DevicePieces() const override;
  void Released(bool mapped) override;

  /// Whether it gave up (the ranks draw their own pieces).
  bool GaveUp() const { return this->Failed; }
  double BeginSeconds = 20.0;  // the longest wait for a rank to begin a frame
  double ImageSeconds = 600.0; // the longest wait for a rank that began to send its image

private:
  vtkSpaceSkipMPIExchange() = default;
  struct Pending;
  void GiveUp(const std::string& why);
  void Reap();
  void Send(std::vector<int> ints, std::vector<float> floats, int dest, int tag);
  int FinishRoot(int width, int height, std::vector<PieceImage>& others);

  vtkSmartPointer<vtkMPIController> Controller;
  int Rank = 0;
  int Size = 1;
  long long Frame = 0;
  bool Failed = false;
  bool VerdictPending = false; // a non-root rank: the verdict of frame Frame is due
  bool VerdictsDue = false;    // rank 0: the verdicts of frame Frame wait for Released()
  // Pieces on the GPUs (CUDA IPC): On once rank 0 mapped this rank's shared image, Off after a
  // failure (host memory from then on).
  enum class DeviceState
  {
    Unknown,
    On,
    Off
  };
  DeviceState Device = DeviceState::Unknown;
  bool OneHost = false;
  bool SentShared = false;   // a non-root rank: its last piece was shared
  std::vector<char> SharedBy; // rank 0: which ranks shared their piece this frame
  std::chrono::steady_clock::time_point BeginTime;
  std::list<Pending> Sends;
  WarnFunction Warn;
};

#endif
