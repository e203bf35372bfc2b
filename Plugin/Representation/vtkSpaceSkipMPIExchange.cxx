#include "vtkSpaceSkipMPIExchange.h"

#include "vtkMPICommunicator.h"
#include "vtkMPIController.h"
#include "vtkMPI.h"

#include <algorithm>
#include <cstring>
#include <thread>

namespace
{
// Tags on the exchange's own communicator.
constexpr int kBeginTag = 11;   // {frame}: a rank began drawing the frame
constexpr int kHeaderTag = 12;  // {frame, width, height, pieces, how, handle (16 ints)}
constexpr int kBoxesTag = 15;   // per piece {x, y, w, h, owned[6]}: its rectangle and cells
constexpr int kDataTag = 13;    // the rectangles' RGBA floats, rows bottom up, piece after piece
// {frame, 1: composited | 0: gave up, 1: the rank's shared image was mapped}, rank 0 to the others
constexpr int kVerdictTag = 14;
constexpr int kVerdictInts = 3;
// how: 0 the pixels follow (kDataTag); 1 one piece shared through CUDA IPC (the handle), no
// pixels; 2 shared, and the pixels follow too (until rank 0 has mapped it once).
constexpr int kHandleInts = 16;
constexpr int kHeaderInts = 5 + kHandleInts;
constexpr int kBoxInts = 10;
constexpr int kMaxPieces = 1 << 16;

using Clock = std::chrono::steady_clock;
using Request = vtkMPICommunicator::Request;

// Polls `reqs` until all completed (true) or `deadline` passed (false; the rest cancelled).
bool WaitAll(std::vector<Request>& reqs, Clock::time_point deadline)
{
  std::vector<char> done(reqs.size(), 0);
  for (;;)
  {
    bool all = true;
    for (size_t i = 0; i < reqs.size(); ++i)
    {
      if (!done[i])
      {
        done[i] = reqs[i].Test() ? 1 : 0;
        all = all && done[i];
      }
    }
    if (all)
    {
      return true;
    }
    if (Clock::now() > deadline)
    {
      for (size_t i = 0; i < reqs.size(); ++i)
      {
        if (!done[i])
        {
          reqs[i].Cancel();
        }
      }
      return false;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
}

Clock::time_point After(double seconds)
{
  return Clock::now() + std::chrono::microseconds(static_cast<long long>(seconds * 1e6));
}
}

struct vtkSpaceSkipMPIExchange::Pending
{
  Request Req;
  std::vector<int> Ints;
  std::vector<float> Floats;
};

//------------------------------------------------------------------------------
std::shared_ptr<vtkSpaceSkipMPIExchange> vtkSpaceSkipMPIExchange::New(
  vtkMultiProcessController* controller, WarnFunction warn, bool oneHost)
{
  auto* mpi = vtkMPIController::SafeDownCast(controller);
  if (!mpi || mpi->GetNumberOfProcesses() < 2)
  {
    return nullptr;
  }
  std::shared_ptr<vtkSpaceSkipMPIExchange> ex(new vtkSpaceSkipMPIExchange);
  // A communicator of its own (MPI_Comm_split, collective): no message of ParaView's can match.
  ex->Controller.TakeReference(mpi->PartitionController(1, mpi->GetLocalProcessId()));
  if (!ex->Controller || !vtkMPICommunicator::SafeDownCast(ex->Controller->GetCommunicator()))
  {
    return nullptr;
  }
  ex->Rank = ex->Controller->GetLocalProcessId();
  ex->Size = ex->Controller->GetNumberOfProcesses();
  ex->Warn = std::move(warn);
  ex->OneHost = oneHost;
  return ex;
}

//------------------------------------------------------------------------------
vtkSpaceSkipMPIExchange::~vtkSpaceSkipMPIExchange() = default;

//------------------------------------------------------------------------------
bool vtkSpaceSkipMPIExchange::NodeLocalRank(vtkMultiProcessController* controller, int& local, int& ranksOnNode)
{
  local = 0;
  ranksOnNode = 1;
  auto* mpi = vtkMPIController::SafeDownCast(controller);
  auto* comm = mpi ? vtkMPICommunicator::SafeDownCast(mpi->GetCommunicator()) : nullptr;
  if (!comm || !comm->GetMPIComm() || !comm->GetMPIComm()->GetHandle())
  {
    return false;
  }
  MPI_Comm node = MPI_COMM_NULL;
  if (MPI_Comm_split_type(*comm->GetMPIComm()->GetHandle(), MPI_COMM_TYPE_SHARED,
        mpi->GetLocalProcessId(), MPI_INFO_NULL, &node) != MPI_SUCCESS ||
    node == MPI_COMM_NULL)
  {
    return false;
  }
  const bool ok = MPI_Comm_rank(node, &local) == MPI_SUCCESS && MPI_Comm_size(node, &ranksOnNode) == MPI_SUCCESS;
  MPI_Comm_free(&node);
  if (!ok)
  {
    local = 0;
    ranksOnNode = 1;
  }
  return ok;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMPIExchange::GiveUp(const std::string& why)
{
  if (this->Failed)
  {
    return;
  }
  this->Failed = true;
  // Sends nobody will receive (a large image waits for its receive) would hold MPI_Finalize.
  for (Pending& p : this->Sends)
  {
    if (!p.Req.Test())
    {
      p.Req.Cancel();
      p.Req.Wait();
    }
  }
  this->Sends.clear();
  this->VerdictsDue = false;
  if (this->Rank == 0)
  {
    for (int r = 1; r < this->Size; ++r)
    {
      this->Send({ static_cast<int>(this->Frame), 0, 0 }, {}, r, kVerdictTag);
    }
  }
  if (this->Warn)
  {
    this->Warn("float compositing of the MPI ranks' pieces is off from now on (" + why +
      "): the ranks' 8-bit images are composited (up to 1/255 per rank off the serial image)");
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMPIExchange::Reap()
{
  this->Sends.remove_if([](Pending& p) { return p.Req.Test() != 0; });
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMPIExchange::Send(std::vector<int> ints, std::vector<float> floats, int dest, int tag)
{
  auto* comm = vtkMPICommunicator::SafeDownCast(this->Controller->GetCommunicator());
  this->Sends.emplace_back();
  Pending& p = this->Sends.back();
  p.Ints = std::move(ints);
  p.Floats = std::move(floats);
  if (!p.Floats.empty())
  {
    comm->NoBlockSend(p.Floats.data(), static_cast<int>(p.Floats.size()), dest, tag, p.Req);
  }
  else
  {
    comm->NoBlockSend(p.Ints.data(), static_cast<int>(p.Ints.size()), dest, tag, p.Req);
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMPIExchange::Begin()
{
  this->Reap();
  if (this->Failed)
  {
    return;
  }
  if (this->Rank == 0)
  {
    this->Released(true); // the verdicts of a frame the mapper did not draw
    ++this->Frame;
    this->BeginTime = Clock::now();
    return;
  }
  if (this->VerdictPending)
  {
    // Rank 0's word on the previous frame: it normally arrived while IceT composited it.
    auto* comm = vtkMPICommunicator::SafeDownCast(this->Controller->GetCommunicator());
    int verdict[kVerdictInts] = { -1, 0, 0 };
    std::vector<Request> req(1);
    comm->NoBlockReceive(verdict, kVerdictInts, 0, kVerdictTag, req[0]);
    if (!WaitAll(req, After(this->BeginSeconds)))
    {
      this->GiveUp("rank 0 did not answer for " + std::to_string(this->BeginSeconds) + " s");
      return;
    }
    this->VerdictPending = false;
    if (verdict[0] != this->Frame || verdict[1] != 1)
    {
      this->GiveUp(verdict[1] != 1 ? "rank 0 gave up" : "the ranks are on different frames");
      return;
    }
    if (this->SentShared)
    {
      // Rank 0 mapped the shared image (or could not: host memory from now on).
      this->Device = verdict[2] == 1 ? DeviceState::On : DeviceState::Off;
    }
  }
  ++this->Frame;
  this->Send({ static_cast<int>(this->Frame) }, {}, 0, kBeginTag);
}

//------------------------------------------------------------------------------
int vtkSpaceSkipMPIExchange::Finish(
  int width, int height, std::vector<PieceImage>& mine, std::vector<PieceImage>& others)
{
  if (this->Failed)
  {
    return -1;
  }
  if (this->Rank == 0)
  {
    return this->FinishRoot(width, height, others);
  }
  std::vector<int> boxes;
  std::vector<float> pixels;
  // One piece shared through CUDA IPC: its handle instead of (or, until rank 0 mapped it once,
  // beside) its pixels.
  const bool shared = mine.size() == 1 && mine[0].Shared;
  const bool withPixels = !shared ||
    mine[0].Pixels.size() == 4 * size_t(std::max(mine[0].Width, 0)) * size_t(std::max(mine[0].Height, 0));
  std::vector<int> header = { static_cast<int>(this->Frame), width, height,
    static_cast<int>(mine.size()), shared ? (withPixels ? 2 : 1) : 0 };
  header.resize(kHeaderInts, 0);
  if (shared)
  {
    static_assert(sizeof(mine[0].Handle) == kHandleInts * sizeof(int), "a handle is 16 ints");
    std::memcpy(&header[5], mine[0].Handle, sizeof(mine[0].Handle));
  }
  this->SentShared = shared;
  for (PieceImage& p : mine)
  {
    boxes.insert(boxes.end(), { p.X, p.Y, p.Width, p.Height });
    boxes.insert(boxes.end(), p.Owned, p.Owned + 6);
    if (withPixels)
    {
      pixels.insert(pixels.end(), p.Pixels.begin(), p.Pixels.end());
    }
  }
  this->Send(std::move(header), {}, 0, kHeaderTag);
  if (!boxes.empty())
  {
    this->Send(std::move(boxes), {}, 0, kBoxesTag);
  }
  if (!pixels.empty())
  {
    this->Send({}, std::move(pixels), 0, kDataTag);
  }
  this->VerdictPending = true;
  return 0;
}

//------------------------------------------------------------------------------
int vtkSpaceSkipMPIExchange::FinishRoot(int width, int height, std::vector<PieceImage>& others)
{
  auto* comm = vtkMPICommunicator::SafeDownCast(this->Controller->GetCommunicator());
  const int n = this->Size - 1;
  // Every rank began this frame (else it is not drawing it: give up, never wait forever).
  std::vector<int> begun(n, -1);
  std::vector<Request> reqs(n);
  // The receives in `reqs` done within ImageSeconds; false: given up, saying `failure`.
  auto imagesArrived = [&](const char* failure) {
    if (WaitAll(reqs, After(this->ImageSeconds)))
    {
      return true;
    }
    this->GiveUp(failure);
    return false;
  };
  for (int r = 1; r < this->Size; ++r)
  {
    comm->NoBlockReceive(&begun[r - 1], 1, r, kBeginTag, reqs[r - 1]);
  }
  const auto beginDeadline = std::max(
    this->BeginTime + std::chrono::microseconds(static_cast<long long>(this->BeginSeconds * 1e6)),
    After(1.0));
  if (!WaitAll(reqs, beginDeadline))
  {
    this->GiveUp("a rank did not draw the frame");
    return -1;
  }
  for (int b : begun)
  {
    if (b != this->Frame)
    {
      this->GiveUp("the ranks are on different frames");
      return -1;
    }
  }
  // What each rank drew: its header, its pieces' rectangles and cells, then their pixels.
  std::vector<int> headers(size_t(n) * kHeaderInts, 0);
  for (int r = 1; r < this->Size; ++r)
  {
    comm->NoBlockReceive(&headers[size_t(r - 1) * kHeaderInts], kHeaderInts, r, kHeaderTag, reqs[r - 1]);
  }
  if (!imagesArrived("a rank did not send its image"))
  {
    return -1;
  }
  std::vector<std::vector<int>> boxes(n);
  reqs.clear();
  for (int r = 1; r < this->Size; ++r)
  {
    const int* h = &headers[size_t(r - 1) * kHeaderInts];
    if (h[0] != this->Frame || h[1] != width || h[2] != height || h[3] < 0 || h[3] > kMaxPieces ||
      h[4] < 0 || h[4] > 2 || (h[4] != 0 && h[3] != 1))
    {
      this->GiveUp(h[0] != this->Frame ? "the ranks are on different frames"
          : h[1] != width || h[2] != height ? "the ranks' viewports differ"
                                            : "a rank sent a bad piece count");
      return -1;
    }
    if (h[3] > 0)
    {
      boxes[r - 1].resize(size_t(h[3]) * kBoxInts);
      reqs.emplace_back();
      comm->NoBlockReceive(boxes[r - 1].data(), static_cast<int>(boxes[r - 1].size()), r, kBoxesTag,
        reqs.back());
    }
  }
  if (!imagesArrived("a rank did not send its pieces"))
  {
    return -1;
  }
  std::vector<std::vector<float>> pixels(n);
  reqs.clear();
  for (int r = 1; r < this->Size; ++r)
  {
    const bool pixelsFollow = headers[size_t(r - 1) * kHeaderInts + 4] != 1;
    size_t total = 0;
    for (size_t k = 0; k < boxes[r - 1].size(); k += kBoxInts)
    {
      const int* b = &boxes[r - 1][k];
      if (b[2] < 0 || b[3] < 0 || (b[2] > 0 && b[3] > 0 &&
        (b[0] < 0 || b[1] < 0 || b[0] + b[2] > width || b[1] + b[3] > height)))
      {
        this->GiveUp("a rank sent a rectangle outside the viewport");
        return -1;
      }
      total += pixelsFollow ? 4 * size_t(b[2]) * size_t(b[3]) : 0;
    }
    if (total > 0)
    {
      pixels[r - 1].resize(total);
      reqs.emplace_back();
      comm->NoBlockReceive(pixels[r - 1].data(), static_cast<int>(total), r, kDataTag, reqs.back());
    }
  }
  if (!imagesArrived("a rank's image did not arrive"))
  {
    return -1;
  }
  others.clear();
  this->SharedBy.assign(size_t(this->Size), 0);
  for (int r = 1; r < this->Size; ++r)
  {
    const int* h = &headers[size_t(r - 1) * kHeaderInts];
    const float* px = pixels[r - 1].data();
    for (size_t k = 0; k < boxes[r - 1].size(); k += kBoxInts)
    {
      const int* b = &boxes[r - 1][k];
      PieceImage p;
      p.X = b[0];
      p.Y = b[1];
      p.Width = b[2];
      p.Height = b[3];
      std::copy(b + 4, b + 10, p.Owned);
      const size_t count = 4 * size_t(std::max(p.Width, 0)) * size_t(std::max(p.Height, 0));
      if (h[4] != 1)
      {
        p.Pixels.assign(px, px + count);
        px += count;
      }
      if (h[4] != 0)
      {
        p.Shared = true;
        p.Source = r;
        std::memcpy(p.Handle, h + 5, sizeof(p.Handle));
        this->SharedBy[size_t(r)] = 1;
      }
      others.push_back(std::move(p));
    }
  }
  // The verdicts go once the mapper has read the pieces (Released): a rank draws its next frame
  // into its shared image only then.
  this->VerdictsDue = true;
  return 1;
}

//------------------------------------------------------------------------------
int vtkSpaceSkipMPIExchange::DevicePieces() const
{
  if (this->Failed || !this->OneHost || this->Device == DeviceState::Off)
  {
    return 0;
  }
  return this->Rank == 0 ? 3 : this->Device == DeviceState::On ? 1 : 2;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMPIExchange::Released(bool mapped)
{
  if (this->Rank != 0 || !this->VerdictsDue || this->Failed)
  {
    return;
  }
  this->VerdictsDue = false;
  for (int r = 1; r < this->Size; ++r)
  {
    const int sharedMapped = mapped && r < static_cast<int>(this->SharedBy.size()) && this->SharedBy[size_t(r)];
    this->Send({ static_cast<int>(this->Frame), 1, sharedMapped }, {}, r, kVerdictTag);
  }
  if (!mapped)
  {
    this->Device = DeviceState::Off;
  }
}
