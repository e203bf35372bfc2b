// vtkSpaceSkipMPIExchange under mpiexec -n 2: the pieces travel whole (frame 1), and a rank that
// does not draw a frame (frame 2: its volume culled, hidden, or an exception) makes both ranks
// give up within the time limit and draw their own pieces, instead of waiting forever.
// Then, on one host, pieces shared through CUDA IPC: the handle travels with the pixels until
// rank 0 has mapped it, then alone; rank 1 draws its next frame only after rank 0 has read the
// last one (Released); a failure to map sends the pixels through host memory again.
#include "vtkSpaceSkipMPIExchange.h"

#include "vtkMPIController.h"
#include "vtkNew.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <string>
#include <thread>

namespace
{
int failures = 0;
void Check(bool ok, int rank, const std::string& what)
{
  std::cout << "rank " << rank << (ok ? ": ok   " : ": FAIL ") << what << std::endl;
  failures += ok ? 0 : 1;
}

// A 300x200 viewport; the piece drew a 40x30 rectangle at (x, 7), cells of a box by rank.
vtkSpaceSkippingVolumeMapper::PieceImage Piece(int rank)
{
  vtkSpaceSkippingVolumeMapper::PieceImage p;
  p.X = 10 + 100 * rank;
  p.Y = 7;
  p.Width = 40;
  p.Height = 30;
  for (int a = 0; a < 6; ++a)
  {
    p.Owned[a] = a == 2 ? 50 * rank : a == 3 ? 50 * (rank + 1) : a % 2 ? 64 : 0;
  }
  p.Pixels.resize(4 * 40 * 30);
  for (size_t i = 0; i < p.Pixels.size(); ++i)
  {
    p.Pixels[i] = 0.001f * float((i * 7 + rank) % 997);
  }
  return p;
}
}

// A piece left on the GPU and shared (the mapper's part: PieceImage::Shared and Handle).
vtkSpaceSkippingVolumeMapper::PieceImage SharedPiece(bool withPixels)
{
  auto p = Piece(1);
  p.X = p.Y = 0;
  p.Width = 300;
  p.Height = 200;
  p.Pixels.assign(withPixels ? 4 * 300 * 200 : 0, 0.25f);
  p.Shared = true;
  for (int i = 0; i < 64; ++i)
  {
    p.Handle[i] = static_cast<char>(i * 3 + 1);
  }
  return p;
}

void SharedPieces(vtkMPIController* controller, int rank)
{
  int warnings = 0;
  auto ex = vtkSpaceSkipMPIExchange::New(
    controller, [&](const std::string&) { ++warnings; }, /*oneHost=*/true);
  ex->BeginSeconds = 5.0;
  ex->ImageSeconds = 5.0;
  using Clock = std::chrono::steady_clock;
  const auto expected = SharedPiece(true);
  // `how` the rank expects to be asked for; rank 0 checks what came and releases (mapped or not)
  // after `hold` seconds.
  auto frame = [&](const char* name, int how, bool send, bool withPixels, bool mapped, double hold) {
    const auto t0 = Clock::now();
    ex->Begin();
    const double began = std::chrono::duration<double>(Clock::now() - t0).count();
    const int asked = ex->DevicePieces();
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> mine;
    if (rank == 0)
    {
      mine.push_back(Piece(0));
    }
    else
    {
      mine.push_back(send ? SharedPiece(withPixels) : Piece(1));
    }
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> others;
    const int r = ex->Finish(300, 200, mine, others);
    if (rank == 0)
    {
      const bool shared = others.size() == 1 && others[0].Shared == send &&
        (!send || (others[0].Source == 1 && std::equal(expected.Handle, expected.Handle + 64, others[0].Handle)));
      const bool pixels = others.size() == 1 &&
        others[0].Pixels.size() == (withPixels ? 4 * size_t(others[0].Width) * size_t(others[0].Height) : 0);
      Check(r == 1 && asked == how && shared && pixels, rank,
        std::string(name) + ": asked " + std::to_string(asked) + ", rank 1's piece as sent");
      std::this_thread::sleep_for(std::chrono::duration<double>(hold));
      ex->Released(mapped);
    }
    else
    {
      Check(r == 0 && asked == how, rank, std::string(name) + ": asked " + std::to_string(asked));
    }
    return began;
  };
  // Rank 1 shares, rank 0 has not mapped it yet: the pixels come too. Rank 0 holds the pieces
  // 0.3 s before it releases them.
  frame("shared 1", rank == 0 ? 3 : 2, true, true, true, 0.3);
  // Mapped: the handle alone. Rank 1's Begin waited for rank 0's release.
  const double began = frame("shared 2", rank == 0 ? 3 : 1, true, false, false, 0.0);
  if (rank == 1)
  {
    Check(began >= 0.25, rank, "rank 1 began frame 'shared 2' after rank 0 released frame 'shared 1' (" +
        std::to_string(began) + " s)");
  }
  // Rank 0 could not map it: host memory again, on both ranks.
  frame("host again", 0, false, true, true, 0.0);
  Check(!ex->GaveUp(), rank, "the exchange goes on after a failed map");
  ex.reset();
}

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  const int rank = controller->GetLocalProcessId();
  int warnings = 0;
  auto ex = vtkSpaceSkipMPIExchange::New(controller, [&](const std::string& m) {
    ++warnings;
    std::cout << "rank " << rank << " warning: " << m << std::endl;
  });
  Check(ex != nullptr && controller->GetNumberOfProcesses() == 2, rank, "an exchange over 2 ranks");
  if (!ex)
  {
    controller->Finalize();
    return 1;
  }
  ex->BeginSeconds = 1.0;
  ex->ImageSeconds = 5.0;
  using Clock = std::chrono::steady_clock;

  // Frame 1: both draw; rank 0 gets rank 1's piece bit for bit and draws the sum.
  {
    ex->Begin();
    // Rank 1 has two pieces (as blocks of partitioned input), the second drew nothing.
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> mine{ Piece(rank) };
    if (rank == 1)
    {
      mine.push_back(Piece(1));
      mine.back().Width = mine.back().Height = 0;
      mine.back().Pixels.clear();
      mine.back().Owned[4] = 64;
    }
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> others;
    const int r = ex->Finish(300, 200, mine, others);
    if (rank == 0)
    {
      const auto expected = Piece(1);
      const bool same = others.size() == 2 && others[0].X == expected.X &&
        others[0].Y == expected.Y && others[0].Width == expected.Width &&
        others[0].Height == expected.Height && others[0].Pixels == expected.Pixels &&
        std::equal(expected.Owned, expected.Owned + 6, others[0].Owned) &&
        others[1].Width == 0 && others[1].Pixels.empty() && others[1].Owned[4] == 64;
      Check(r == 1 && same, rank, "frame 1: rank 0 composites and has rank 1's 2 pieces as sent");
    }
    else
    {
      Check(r == 0, rank, "frame 1: rank 1 draws nothing (rank 0 draws its piece)");
    }
  }
  // Frame 2: rank 1 does not draw it. Rank 0 gives up after BeginSeconds, not forever.
  if (rank == 0)
  {
    const auto t0 = Clock::now();
    ex->Begin();
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> mine{ Piece(0) };
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> others;
    const int r = ex->Finish(300, 200, mine, others);
    const double waited = std::chrono::duration<double>(Clock::now() - t0).count();
    Check(r == -1 && ex->GaveUp() && warnings == 1, rank,
      "frame 2: rank 1 missing: rank 0 gives up and draws its own piece, one warning");
    Check(waited >= 0.9 && waited < 5.0, rank,
      "frame 2: rank 0 waited " + std::to_string(waited) + " s (limit 1 s)");
  }
  // Rank 1's next frames: it learns that rank 0 gave up and draws its own piece.
  if (rank == 1)
  {
    // Not drawing rank 0's frame 2: it comes back later than the limit.
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
    int r = 0;
    for (int frame = 0; frame < 2 && r != -1; ++frame)
    {
      ex->Begin();
      std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> mine{ Piece(1) };
      std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> others;
      r = ex->Finish(300, 200, mine, others);
    }
    Check(r == -1 && ex->GaveUp() && warnings == 1, rank,
      "rank 1 gives up within 2 frames and draws its own piece, one warning");
  }
  // Both carry on (8-bit path) without waiting.
  {
    const auto t0 = Clock::now();
    ex->Begin();
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> mine{ Piece(rank) };
    std::vector<vtkSpaceSkippingVolumeMapper::PieceImage> others;
    const int r = ex->Finish(300, 200, mine, others);
    const double waited = std::chrono::duration<double>(Clock::now() - t0).count();
    Check(r == -1 && waited < 0.5, rank, "after giving up: no wait, own piece drawn");
  }
  ex.reset();
  SharedPieces(controller, rank);
  controller->Barrier();
  controller->Finalize();
  return failures == 0 ? 0 : 1;
}
