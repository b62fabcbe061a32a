// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The cut field's reader/writer contract; also run under ThreadSanitizer
// (Utilities/vc test builds build/tsan for it).
#include "vtkVolumeCutField.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <algorithm>
#include <atomic>
#include <thread>

namespace
{
// One writer cutting while a reader copies the brick it cuts through: with
// cuts only, no stored sample may ever grow, and a copy is never half-written
// (a torn copy would mix samples of two states and could show one grow).
int TestConcurrentReaderAndWriter()
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRas->SetElement(axis, axis, 0.5);
  }
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  const double watched[4] = { 12.0, 12.0, 12.0, 1.0 };
  vtkNew<vtkMatrix4x4> subToRas;
  vtkNew<vtkMatrix4x4> rasToSub;
  field->GetSubVoxelIJKToRAS(subToRas);
  vtkMatrix4x4::Invert(subToRas, rasToSub);
  double index[4];
  rasToSub->MultiplyPoint(watched, index);
  const int* brickDims = field->GetBrickDimensions();
  const int b[3] = { int(index[0]) / vtkVolumeCutField::BrickSize, int(index[1]) / vtkVolumeCutField::BrickSize,
    int(index[2]) / vtkVolumeCutField::BrickSize };
  const vtkIdType brickId = (static_cast<vtkIdType>(b[2]) * brickDims[1] + b[1]) * brickDims[0] + b[0];

  std::atomic<bool> done{ false };
  std::atomic<bool> consistent{ true };
  std::atomic<int> copies{ 0 };
  std::thread reader([&]() {
    short previous[512];
    short current[512];
    vtkTypeUInt64 previousStamp = field->CopyBrick(brickId, previous);
    while (!done.load())
    {
      const vtkTypeUInt64 stamp = field->CopyBrick(brickId, current);
      for (int n = 0; n < 512; ++n)
      {
        if (current[n] > previous[n] || stamp < previousStamp)
        {
          consistent = false;
        }
      }
      std::copy(current, current + 512, previous);
      previousStamp = stamp;
      field->GetSignedDistance(watched);
      ++copies;
    }
  });
  for (int n = 0; n < 400; ++n)
  {
    const double t = n / 400.0;
    const double p0[3] = { 4.0 + 16.0 * t, 12.0, 12.0 };
    const double p1[3] = { 4.0 + 16.0 * (t + 1.0 / 400.0), 12.0, 12.0 };
    field->CutCapsule(p0, p1, 1.5);
  }
  done = true;
  reader.join();
  CHECK_BOOL(consistent.load(), true);
  CHECK_BOOL(copies.load() > 0, true);
  CHECK_BOOL(field->GetSignedDistance(watched) < 0.0, true);
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutFieldThreadTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestConcurrentReaderAndWriter());
  return EXIT_SUCCESS;
}
