// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Whether the trilinear CT reaches an iso-value between two samples decides
// whether the ray caster looks for a border hidden there: a wrong "no"
// loses a grazed surface from the image, a needless "yes" costs sixteen
// classified parts. Checked against dense sampling of the same trilinear
// function on random data and segments crossing up to several cells.
#include "vtkVolumeCutSampleClassifier.h"

#include <vtkAddonTestingMacros.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

int vtkVolumeCutSampleClassifierTest1(int, char*[])
{
  vtkVolumeCutRayScene scene;
  const int n = 7;
  scene.Dimensions[0] = scene.Dimensions[1] = scene.Dimensions[2] = n;
  std::mt19937 random(20261124);
  std::uniform_real_distribution<float> hounsfield(-200.f, 900.f);
  scene.Values.resize(n * n * n);
  for (float& value : scene.Values)
  {
    value = hounsfield(random);
  }
  const vtkVolumeCutSampleClassifier classifier(scene);
  std::uniform_real_distribution<double> position(0.0, n - 1.0);
  std::uniform_real_distribution<double> offset(-1.5, 1.5);
  std::uniform_real_distribution<double> level(0.0, 800.0);
  int missed = 0;
  int needless = 0;
  int reached = 0;
  const int segments = 20000;
  for (int s = 0; s < segments; ++s)
  {
    double p[3], q[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      p[axis] = position(random);
      q[axis] = std::min(n - 1.0, std::max(0.0, p[axis] + offset(random)));
    }
    if (s % 10 == 0)
    {
      q[s % 3] = p[s % 3]; // parallel to a cell wall
    }
    float maximum = -1e30f;
    const int samples = 4000;
    for (int i = 0; i <= samples; ++i)
    {
      const double t = double(i) / samples;
      const double x[3] = { p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2]) };
      maximum = std::max(maximum, classifier.Interpolate(x));
    }
    if (classifier.MaximumAround(p, q) < maximum)
    {
      std::cerr << "MaximumAround " << classifier.MaximumAround(p, q) << " is below a value on the segment, " << maximum << std::endl;
      return EXIT_FAILURE;
    }
    const float iso = static_cast<float>(level(random));
    const bool reaches = classifier.Reaches(p, q, iso);
    reached += reaches;
    // Dense sampling may fall just short of a thin maximum: a margin of a
    // thousandth of a unit separates its errors from the test's.
    if (maximum >= iso + 1e-3f && !reaches)
    {
      ++missed;
    }
    if (maximum < iso - 1.0f && reaches)
    {
      ++needless;
    }
  }
  std::cout << reached << " of " << segments << " segments reach their level; missed " << missed << ", needless " << needless << std::endl;
  CHECK_INT(missed, 0);
  // A segment whose dense maximum lies a whole unit below the level never
  // reaches it: the test is exact, not a bound.
  CHECK_INT(needless, 0);
  CHECK_BOOL(reached > segments / 10, true);

  // The dominant label of cells where segments meet, decided without the
  // general weighing, must decide as it does (ties and bright unlabelled
  // material included).
  std::uniform_int_distribution<int> labelOf(0, 3);
  scene.Labels.resize(scene.Values.size());
  for (uint16_t& label : scene.Labels)
  {
    label = static_cast<uint16_t>(labelOf(random));
  }
  scene.AnyIsoSegment = true;
  scene.MinimumIso = 300.0;
  int differences = 0;
  for (int s = 0; s < segments; ++s)
  {
    double p[3] = { position(random), position(random), position(random) };
    if (s % 7 == 0)
    {
      p[s % 3] = std::floor(p[s % 3]) + 0.5; // equal weights: ties
    }
    double weight = 0.0;
    const int label = classifier.DominantLabel(p, weight);
    double unlabelledBright = 0.0;
    double referenceWeight = 0.0;
    int reference = classifier.StrongestLabel(
      p,
      [&](int corner, vtkIdType voxel, double w) {
        if (corner == 0)
        {
          unlabelledBright += scene.Values[voxel] >= scene.MinimumIso ? w : 0.0;
          return false;
        }
        return true;
      },
      [](int) { return true; }, referenceWeight);
    reference = unlabelledBright > referenceWeight ? 0 : reference;
    differences += label != reference || (label != 0 && weight != referenceWeight);
  }
  std::cout << "dominant label differs from the general weighing at " << differences << " of " << segments << " points" << std::endl;
  CHECK_INT(differences, 0);
  return EXIT_SUCCESS;
}
