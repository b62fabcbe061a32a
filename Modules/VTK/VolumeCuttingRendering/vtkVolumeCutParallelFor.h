// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
#ifndef vtkVolumeCutParallelFor_h
#define vtkVolumeCutParallelFor_h

#include <vtkSMPTools.h>

#include <cstring>

/// vtkSMPTools::For over [0, end) with at most maximumThreads threads (0: all
/// cores). The VTK wheels start on the Sequential backend, which would leave a
/// CPU reference that is meant to be multithreaded on one core: there the
/// standard-thread backend is used for these loops only. Slicer's own build
/// runs TBB and keeps it.
template <typename Work>
void vtkVolumeCutParallelFor(int maximumThreads, vtkIdType end, Work&& work)
{
  if (maximumThreads == 1)
  {
    work(vtkIdType(0), end);
    return;
  }
  vtkSMPTools::Config config; // the active backend
  if (std::strcmp(vtkSMPTools::GetBackend(), "Sequential") == 0)
  {
    config.Backend = "STDThread";
  }
  config.MaxNumberOfThreads = maximumThreads;
  vtkSMPTools::LocalScope(config, [&] { vtkSMPTools::For(0, end, work); });
}

#endif
