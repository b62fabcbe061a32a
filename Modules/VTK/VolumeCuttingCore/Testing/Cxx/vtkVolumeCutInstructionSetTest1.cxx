// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Every instruction set this build and processor have writes bitwise the same
// field (a replay recorded on one machine cuts the same on another), for
// every kind of stroke; the widest set is the one used by default.
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutEllipsoidTool.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutPrismTool.h"

#include <vtkAddonTestingMacros.h>

#include <vtkIdList.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkTransform.h>

#include <iostream>
#include <map>
#include <vector>

namespace
{
using Snapshot = std::map<vtkIdType, std::vector<short>>;

/// Strokes of every kind on an oblique, anisotropic grid; the field's bricks.
Snapshot CutEverything(double& removedVolume)
{
  vtkNew<vtkTransform> grid;
  grid->Translate(-3.0, 2.0, 1.0);
  grid->RotateWXYZ(23.0, 0.3, 1.0, 0.2);
  grid->Scale(0.6, 0.65, 0.8);
  vtkNew<vtkVolumeCutField> field;
  const int dims[3] = { 36, 34, 26 };
  field->Initialize(dims, grid->GetMatrix(), 2);

  // A burr path: fresh strokes, continued ones, a restore across it.
  double previous[3] = { 4.0, 6.0, 7.0 };
  for (int n = 1; n <= 40; ++n)
  {
    const double next[3] = { 4.0 + 0.3 * n, 6.0 + 0.1 * n, 7.0 + 0.05 * n };
    field->CutCapsule(previous, next, 2.0);
    std::copy(next, next + 3, previous);
  }
  const double restoreFrom[3] = { 8.0, 7.0, 8.0 };
  const double restoreTo[3] = { 9.0, 8.0, 8.5 };
  field->RestoreCapsule(restoreFrom, restoreTo, 1.2);

  // Tools swept with rotation: the tool-frame, merge and shape loops.
  vtkNew<vtkVolumeCutCylinderTool> cylinder;
  cylinder->SetRadius(1.5);
  cylinder->SetLength(3.0);
  vtkNew<vtkVolumeCutEllipsoidTool> ellipsoid;
  ellipsoid->SetRadii(1.0, 1.8, 2.5);
  vtkNew<vtkVolumeCutBoxTool> blade;
  blade->SetSize(6.0, 0.4, 3.0);
  vtkNew<vtkVolumeCutPrismTool> prism;
  prism->AddVertex(-1.0, -1.0);
  prism->AddVertex(1.5, -1.0);
  prism->AddVertex(0.0, 1.5);
  prism->SetDepth(2.0);
  vtkVolumeCutTool* tools[] = { cylinder, ellipsoid, blade, prism };
  double y = 3.0;
  for (vtkVolumeCutTool* tool : tools)
  {
    vtkNew<vtkTransform> start;
    start->Translate(3.0, y, 12.0);
    vtkNew<vtkTransform> end;
    end->Translate(5.0, y + 0.5, 12.5);
    end->RotateWXYZ(20.0, 0.2, 0.5, 1.0);
    field->CutToolSweep(tool, start->GetMatrix(), end->GetMatrix());
    y += 4.5;
  }
  // Pure translations continued pose to pose, as a haptic stroke makes
  // them: the cylinder's closed-form sweep (across and along its axis) and
  // the regions the tools leave behind.
  vtkNew<vtkVolumeCutCylinderTool> disk;
  disk->SetRadius(3.0);
  disk->SetLength(0.5);
  vtkVolumeCutTool* translated[] = { cylinder, disk, blade };
  double z = 4.0;
  for (vtkVolumeCutTool* tool : translated)
  {
    vtkNew<vtkMatrix4x4> previous;
    for (int n = 0; n <= 12; ++n)
    {
      vtkNew<vtkTransform> pose;
      pose->Translate(9.0 + 0.4 * n, 13.0 + 0.25 * n, z + (n < 6 ? 0.0 : 0.3 * (n - 6)));
      pose->RotateWXYZ(35.0, 1.0, 0.3, 0.0);
      field->CutToolSweep(tool, n == 0 ? pose->GetMatrix() : previous.GetPointer(), pose->GetMatrix());
      previous->DeepCopy(pose->GetMatrix());
    }
    z += 3.5;
  }

  vtkNew<vtkTransform> restorePose;
  restorePose->Translate(6.0, 8.0, 12.5);
  field->RestoreToolSweep(ellipsoid, restorePose->GetMatrix(), restorePose->GetMatrix());

  removedVolume = field->ComputeRemovedVolume();
  Snapshot bricks;
  vtkNew<vtkIdList> ids;
  field->GetBricksModifiedSince(0, ids);
  for (vtkIdType n = 0; n < ids->GetNumberOfIds(); ++n)
  {
    std::vector<short>& values = bricks[ids->GetId(n)];
    values.resize(vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize);
    field->CopyBrick(ids->GetId(n), values.data());
  }
  return bricks;
}
}

int vtkVolumeCutInstructionSetTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  const int initial = vtkVolumeCutField::GetInstructionSet();
  int widest = vtkVolumeCutField::InstructionSetBaseline;
  for (int set = vtkVolumeCutField::InstructionSetBaseline; set <= vtkVolumeCutField::InstructionSetAVX512; ++set)
  {
    if (vtkVolumeCutField::IsInstructionSetAvailable(set))
    {
      widest = set;
    }
  }
  CHECK_INT(initial, widest);
  CHECK_BOOL(vtkVolumeCutField::IsInstructionSetAvailable(vtkVolumeCutField::InstructionSetBaseline), true);
  CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(17), false);
  CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(-1), false);
  CHECK_INT(vtkVolumeCutField::GetInstructionSet(), initial);

  CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(vtkVolumeCutField::InstructionSetBaseline), true);
  double baselineVolume = 0.0;
  const Snapshot baseline = CutEverything(baselineVolume);
  // Something to compare: the strokes cut and restored many bricks.
  CHECK_BOOL(baseline.size() > 40, true);
  CHECK_BOOL(baselineVolume > 100.0, true);

  int compared = 0;
  for (int set = vtkVolumeCutField::InstructionSetAVX2; set <= vtkVolumeCutField::InstructionSetAVX512; ++set)
  {
    if (!vtkVolumeCutField::IsInstructionSetAvailable(set))
    {
      CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(set), false);
      continue;
    }
    CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(set), true);
    CHECK_INT(vtkVolumeCutField::GetInstructionSet(), set);
    double volume = 0.0;
    const Snapshot bricks = CutEverything(volume);
    if (bricks != baseline || volume != baselineVolume)
    {
      int differing = 0;
      for (const auto& brick : bricks)
      {
        const auto other = baseline.find(brick.first);
        differing += other == baseline.end() || other->second != brick.second;
      }
      std::cerr << vtkVolumeCutField::GetInstructionSetAsString(set) << ": " << differing << " of " << bricks.size()
                << " bricks differ from the baseline's " << baseline.size() << "; removed volume " << volume << " vs " << baselineVolume
                << " mm^3" << std::endl;
      vtkVolumeCutField::SetInstructionSet(initial);
      return EXIT_FAILURE;
    }
    ++compared;
  }
  std::cout << "instruction sets compared with the baseline: " << compared << " (in use: " << vtkVolumeCutField::GetInstructionSetAsString(initial)
            << ")" << std::endl;
  CHECK_BOOL(vtkVolumeCutField::SetInstructionSet(initial), true);
  return EXIT_SUCCESS;
}
