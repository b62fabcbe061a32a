// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticVibration.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkHapticVibration);

namespace
{
constexpr double TwoPi = 6.283185307179586;
}

//------------------------------------------------------------------------------
void vtkHapticVibration::ConfigureCuttingBurr()
{
  this->IdleAmplitude = 0.05;
  this->AmplitudePerNewton = 0.08;
  this->MaximumAmplitude = 0.6;
  this->IdleFrequency = 180.0;
  this->FrequencyPerNewton = -12.0;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkHapticVibration::ConfigureDiamondBurr()
{
  this->IdleAmplitude = 0.02;
  this->AmplitudePerNewton = 0.03;
  this->MaximumAmplitude = 0.25;
  this->IdleFrequency = 240.0;
  this->FrequencyPerNewton = -8.0;
  this->Modified();
}

//------------------------------------------------------------------------------
double vtkHapticVibration::Evaluate(double contactForce, double timeStep, double maximumFrequency, double maximumAmplitude)
{
  const double force = std::isfinite(contactForce) ? std::max(0.0, contactForce) : 0.0;
  double frequency = std::max(0.0, this->IdleFrequency + this->FrequencyPerNewton * force);
  double amplitude = std::min(this->MaximumAmplitude, this->IdleAmplitude + this->AmplitudePerNewton * force);
  frequency = std::min(frequency, std::max(0.0, maximumFrequency));
  amplitude = std::min(amplitude, std::max(0.0, maximumAmplitude));
  if (!(frequency > 0.0) || !(amplitude > 0.0) || !(timeStep > 0.0) || !std::isfinite(timeStep))
  {
    this->LastFrequency = 0.0;
    this->LastAmplitude = 0.0;
    return 0.0;
  }
  this->Phase = std::fmod(this->Phase + TwoPi * frequency * timeStep, TwoPi);
  this->LastFrequency = frequency;
  this->LastAmplitude = amplitude;
  return amplitude * std::sin(this->Phase);
}

//------------------------------------------------------------------------------
void vtkHapticVibration::Reset()
{
  this->Phase = 0.0;
  this->LastFrequency = 0.0;
  this->LastAmplitude = 0.0;
}

//------------------------------------------------------------------------------
void vtkHapticVibration::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "IdleAmplitude: " << this->IdleAmplitude << " N\n";
  os << indent << "AmplitudePerNewton: " << this->AmplitudePerNewton << "\n";
  os << indent << "MaximumAmplitude: " << this->MaximumAmplitude << " N\n";
  os << indent << "IdleFrequency: " << this->IdleFrequency << " Hz\n";
  os << indent << "FrequencyPerNewton: " << this->FrequencyPerNewton << " Hz/N\n";
}
