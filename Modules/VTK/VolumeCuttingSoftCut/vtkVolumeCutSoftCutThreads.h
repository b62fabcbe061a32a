// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingSoftCut (not installed, not wrapped): the module's
// parallel loops on every core.
#ifndef vtkVolumeCutSoftCutThreads_h
#define vtkVolumeCutSoftCutThreads_h

#include "vtkSMPTools.h"

#include <cstring>

namespace vtkVolumeCutSoftCutThreads
{
/**
 * vtkSMPTools::For over [begin, end). The VTK wheels start on the Sequential
 * back end, which would plan a resection on one core of the two or more a
 * planning session has: there these loops run on the standard-thread back
 * end; a build configured with another back end (Slicer's TBB) keeps it.
 */
template <typename Work>
void For(vtkIdType begin, vtkIdType end, Work&& work)
{
  if (std::strcmp(vtkSMPTools::GetBackend(), "Sequential") != 0)
  {
    vtkSMPTools::For(begin, end, work);
    return;
  }
  vtkSMPTools::Config config;
  config.Backend = "STDThread";
  vtkSMPTools::LocalScope(config, [&] { vtkSMPTools::For(begin, end, work); });
}
} // namespace vtkVolumeCutSoftCutThreads

#endif
