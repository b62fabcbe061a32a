// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Forces forwarded between two running haptic loops, also run under
// ThreadSanitizer: each loop's thread ticks its coupling (UDP on loopback,
// 5 ms injected delay, 10 % loss), a hand thread per device moves its
// handle under the force the loop commands, and the main thread reads the
// couplings' and loops' display values meanwhile. The coupling must engage
// (packets accepted both ways, a pull felt) and never ask for more than
// the device's maximum.
#include "vtkHapticTestScene.h"

#include "vtkHapticCoupling.h"
#include "vtkHapticCouplingTransport.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

int vtkHapticCouplingThreadTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkHapticTestScene scene;
  vtkNew<vtkVirtualHapticDevice> devices[2];
  vtkNew<vtkHapticForceModel> models[2];
  vtkNew<vtkHapticLoop> loops[2];
  vtkNew<vtkHapticCoupling> couplings[2];
  vtkNew<vtkHapticCouplingTransport> transports[2];
  CHECK_BOOL(transports[1]->Open("127.0.0.1", 0, "127.0.0.1", 9), true);
  CHECK_BOOL(transports[0]->Open("127.0.0.1", 0, "127.0.0.1", transports[1]->GetLocalPort()), true);
  CHECK_BOOL(transports[1]->Open("127.0.0.1", transports[1]->GetLocalPort(), "127.0.0.1", transports[0]->GetLocalPort()), true);
  for (int side = 0; side < 2; ++side)
  {
    models[side]->SetAnatomy(scene.CT, scene.IJKToRAS);
    models[side]->SetSurfaceIsoValue(scene.IsoValue);
    models[side]->SetSphereRadius(2.0);
    loops[side]->SetDevice(devices[side]);
    loops[side]->SetForceModel(models[side]);
    vtkNew<vtkMatrix4x4> deviceToRAS;
    deviceToRAS->SetElement(2, 3, scene.PlaneHeight + 10.0);
    loops[side]->SetDeviceToRAS(deviceToRAS);
    loops[side]->SetStatisticsCapacity(4096);
    transports[side]->SetInjectedDelay(0.005);
    transports[side]->SetInjectedLossRate(0.1);
    transports[side]->SetInjectionSeed(side + 1);
    couplings[side]->SetTransport(transports[side]);
    couplings[side]->SetEngageTime(0.05);
    loops[side]->SetCoupling(couplings[side]);
    CHECK_BOOL(devices[side]->Open(), true);
    const double start[3] = { side == 0 ? 0.0 : 4.0, 0.0, 0.0 };
    devices[side]->SetPose(start, 0u);
    CHECK_BOOL(loops[side]->Start(), true);
  }

  // The hands: the instructor's circles, the trainee's is moved by the force it feels (a damped 0.1 kg handle).
  std::atomic<bool> done{ false };
  std::thread hands[2];
  for (int side = 0; side < 2; ++side)
  {
    hands[side] = std::thread([&, side]() {
      double position[3] = { side == 0 ? 0.0 : 4.0, 0.0, 0.0 };
      double velocity[3] = { 0.0, 0.0, 0.0 };
      auto last = std::chrono::steady_clock::now();
      for (int step = 0; !done.load(); ++step)
      {
        std::this_thread::sleep_for(std::chrono::microseconds(500));
        const auto now = std::chrono::steady_clock::now();
        const double dt = std::min(0.005, std::chrono::duration<double>(now - last).count());
        last = now;
        if (side == 0)
        {
          const double angle = 0.003 * step;
          position[0] = 5.0 * std::sin(angle);
          position[1] = 5.0 * (1.0 - std::cos(angle));
        }
        else
        {
          double force[3];
          devices[side]->GetCommandedForce(force);
          for (int axis = 0; axis < 3; ++axis)
          {
            velocity[axis] += dt * 1000.0 * (force[axis] - 0.004 * velocity[axis]) / 0.1;
            position[axis] += dt * velocity[axis];
          }
        }
        devices[side]->SetPose(position, 0u);
      }
    });
  }

  // The main thread at display rate.
  double largest = 0.0;
  double largestLoopForce = 0.0;
  double peerGap = 1e300;
  for (int frame = 0; frame < 60 || (frame < 6000 && (transports[0]->GetNumberOfPacketsAccepted() < 100 ||
                                                        transports[1]->GetNumberOfPacketsAccepted() < 100));
       ++frame)
  {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    for (int side = 0; side < 2; ++side)
    {
      double force[3];
      couplings[side]->GetLatestForce(force);
      largest = std::max(largest, vtkMath::Norm(force));
      loops[side]->GetLatestForce(force);
      largestLoopForce = std::max(largestLoopForce, vtkMath::Norm(force));
      couplings[side]->GetLatestTank();
      couplings[side]->GetLatestGain();
      couplings[side]->GetLatestPeerAge();
      double peer[3];
      if (side == 1 && couplings[side]->GetLatestPeerPosition(peer))
      {
        peerGap = std::min(peerGap, std::abs(peer[2] - (scene.PlaneHeight + 10.0)));
      }
      loops[side]->ProcessEvents();
      devices[side]->ProcessConnectionEvents();
    }
  }
  done = true;
  for (std::thread& hand : hands)
  {
    hand.join();
  }
  for (vtkHapticLoop* loop : { loops[0].GetPointer(), loops[1].GetPointer() })
  {
    loop->Stop();
  }
  const double maximum = devices[0]->GetCapabilities()->GetMaximumForce();
  std::cout << "accepted " << transports[0]->GetNumberOfPacketsAccepted() << " / " << transports[1]->GetNumberOfPacketsAccepted()
            << " packets, lost by injection " << transports[0]->GetNumberOfPacketsLostByInjection() << " / "
            << transports[1]->GetNumberOfPacketsLostByInjection() << "; largest coupling force " << largest << " N; updates "
            << couplings[0]->GetNumberOfUpdates() << ", p99 " << couplings[0]->GetUpdateDurationPercentile(99.0) << " us" << std::endl;
  CHECK_BOOL(transports[0]->GetNumberOfPacketsAccepted() >= 100 && transports[1]->GetNumberOfPacketsAccepted() >= 100, true);
  CHECK_BOOL(transports[0]->GetNumberOfPacketsLostByInjection() > 0, true);
  CHECK_BOOL(largest > 0.0 && largest <= maximum, true);
  CHECK_BOOL(largestLoopForce <= maximum, true);
  // The peer's proxy arrives in the scene's frame, at the handle's height.
  CHECK_BOOL(peerGap < 1e-6, true);
  CHECK_BOOL(couplings[0]->GetNumberOfUpdates() > 0, true);
  return EXIT_SUCCESS;
}
