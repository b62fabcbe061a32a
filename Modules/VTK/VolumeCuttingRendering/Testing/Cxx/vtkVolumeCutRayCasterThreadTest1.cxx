// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The renderer reads a cut field while the haptic thread cuts it: no locks on
// the writer, no torn reads (ThreadSanitizer runs this in build/tsan), and
// localized updates miss nothing a concurrent stroke changed.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRayCaster.h"

#include <vtkAddonTestingMacros.h>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <atomic>
#include <cmath>
#include <iostream>
#include <thread>

namespace
{
constexpr int N = 32;
constexpr int Pixels = 48;

void MakeBall(vtkImageData* image)
{
  image->SetDimensions(N, N, N);
  image->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(image->GetScalarPointer());
  for (int k = 0; k < N; ++k)
  {
    for (int j = 0; j < N; ++j)
    {
      for (int i = 0; i < N; ++i)
      {
        const double r = std::sqrt((i - 15.5) * (i - 15.5) + (j - 15.5) * (j - 15.5) + (k - 15.5) * (k - 15.5));
        values[(k * N + j) * N + i] = static_cast<float>(1000.0 * std::min(1.0, std::max(0.0, 0.5 - (r - 12.0) / 2.0)));
      }
    }
  }
}

void MakeCamera(vtkMatrix4x4* worldToNDC)
{
  // Parallel projection down -z over the ball (1 mm voxels).
  worldToNDC->Identity();
  worldToNDC->SetElement(0, 0, 1.0 / 16.0);
  worldToNDC->SetElement(0, 3, -15.5 / 16.0);
  worldToNDC->SetElement(1, 1, 1.0 / 16.0);
  worldToNDC->SetElement(1, 3, -15.5 / 16.0);
  worldToNDC->SetElement(2, 2, -2.0 / 100.0);
  worldToNDC->SetElement(2, 3, 2.0 * (80.0 - 10.0) / 100.0 - 1.0);
}
}

int vtkVolumeCutRayCasterThreadTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkImageData> ct;
  MakeBall(ct);
  vtkNew<vtkMatrix4x4> ijkToRas;
  const int dims[3] = { N, N, N };
  vtkNew<vtkVolumeCutField> cut;
  CHECK_BOOL(cut->Initialize(dims, ijkToRas, 2), true);
  vtkNew<vtkVolumeCutRayCaster> caster;
  caster->SetAnatomy(ct, ijkToRas);
  caster->SetIsoValue(500.0);
  caster->AddCutField(cut);
  // The test's two threads are the point; the caster's own row threads are
  // VTK's (not instrumented), so rows run in this thread here.
  caster->SetMaximumNumberOfThreads(1);
  vtkNew<vtkMatrix4x4> camera;
  MakeCamera(camera);
  CHECK_BOOL(caster->Render(camera, Pixels, Pixels), true);

  std::atomic<bool> done(false);
  std::thread writer([&cut, &done]() {
    for (int stroke = 0; stroke < 200; ++stroke)
    {
      const double t = stroke / 200.0 * 6.283185307179586;
      const double p0[3] = { 15.5 + 8.0 * std::cos(t), 15.5 + 8.0 * std::sin(t), 27.5 };
      const double p1[3] = { 15.5 + 8.0 * std::cos(t + 0.03), 15.5 + 8.0 * std::sin(t + 0.03), 27.5 };
      cut->CutCapsule(p0, p1, 2.5);
    }
    done = true;
  });
  int frames = 0;
  while (!done)
  {
    if (!caster->Render(camera, Pixels, Pixels))
    {
      writer.join();
      return EXIT_FAILURE;
    }
    ++frames;
  }
  writer.join();
  CHECK_BOOL(caster->Render(camera, Pixels, Pixels), true);
  std::cout << frames << " frames while the writer cut" << std::endl;

  // After the last localized update the image equals a full render.
  vtkNew<vtkVolumeCutRayCaster> fresh;
  fresh->SetAnatomy(ct, ijkToRas);
  fresh->SetIsoValue(500.0);
  fresh->AddCutField(cut);
  fresh->SetMaximumNumberOfThreads(1);
  CHECK_BOOL(fresh->Render(camera, Pixels, Pixels), true);
  for (int p = 0; p < Pixels * Pixels * 4; ++p)
  {
    if (caster->GetColorBuffer()[p] != fresh->GetColorBuffer()[p])
    {
      std::cerr << "pixel " << p / 4 << " differs from a full render after concurrent cutting" << std::endl;
      return EXIT_FAILURE;
    }
  }
  return EXIT_SUCCESS;
}
