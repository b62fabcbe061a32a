// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticVibration
 * @brief   Drill vibration whose amplitude and frequency follow the force.
 *
 * Seed 003 records a drill's vibration per burr type and applied force and
 * finds sharp spectral peaks whose low ones a 1 kHz haptic device can
 * render. This synthesises the fundamental: a sine along the tool's axis
 * whose amplitude and frequency are linear in the contact force,
 *
 *     amplitude = IdleAmplitude + AmplitudePerNewton * force   (<= MaximumAmplitude)
 *     frequency = IdleFrequency + FrequencyPerNewton * force
 *
 * with a running phase, so that a change of frequency never jumps. What the
 * device cannot render is left out: the frequency is held below a quarter
 * of the slower of the loop's and the device's rates (four samples a
 * period), and the amplitude below what the device's maximum force leaves
 * after the contact force.
 *
 * The presets are illustrative, not measured here: cutting burrs chatter
 * harder and slower than diamond burrs, which run smoother (seed 003, Fig.
 * 1); the figures are meant to be tuned, as the seed's otologist did.
 *
 * Evaluate runs on the haptic thread; set the parameters while no loop runs.
 *
 * @sa vtkHapticForceModel
 */

#ifndef vtkHapticVibration_h
#define vtkHapticVibration_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticVibration : public vtkObject
{
public:
  static vtkHapticVibration* New();
  vtkTypeMacro(vtkHapticVibration, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the amplitude (N) of a running drill out of contact, and its
   * growth per newton of contact force (N/N). Defaults are 0.05 and 0.08.
   */
  vtkSetClampMacro(IdleAmplitude, double, 0.0, 100.0);
  vtkGetMacro(IdleAmplitude, double);
  vtkSetClampMacro(AmplitudePerNewton, double, 0.0, 100.0);
  vtkGetMacro(AmplitudePerNewton, double);
  ///@}

  ///@{
  /**
   * Set/get the largest amplitude (N). Default is 0.6.
   */
  vtkSetClampMacro(MaximumAmplitude, double, 0.0, 100.0);
  vtkGetMacro(MaximumAmplitude, double);
  ///@}

  ///@{
  /**
   * Set/get the frequency (Hz) out of contact and its change per newton of
   * contact force (a loaded burr slows down: negative). Defaults are 180 and -12.
   */
  vtkSetClampMacro(IdleFrequency, double, 0.0, 1.0e5);
  vtkGetMacro(IdleFrequency, double);
  vtkSetClampMacro(FrequencyPerNewton, double, -1.0e4, 1.0e4);
  vtkGetMacro(FrequencyPerNewton, double);
  ///@}

  ///@{
  /**
   * Presets per burr type (see the class description).
   */
  void ConfigureCuttingBurr();
  void ConfigureDiamondBurr();
  ///@}

  /**
   * The vibration force (N, signed, along the tool's axis) for this tick,
   * advancing the phase by timeStep seconds at the force's frequency.
   * maximumFrequency and maximumAmplitude are what the device can render
   * now (see the class description); zero when either is not positive.
   */
  double Evaluate(double contactForce, double timeStep, double maximumFrequency, double maximumAmplitude);

  /// The frequency (Hz) and amplitude (N) Evaluate used last.
  vtkGetMacro(LastFrequency, double);
  vtkGetMacro(LastAmplitude, double);

  /// Restart the phase (a new drilling run).
  void Reset();

protected:
  vtkHapticVibration() = default;
  ~vtkHapticVibration() override = default;

  double IdleAmplitude = 0.05;
  double AmplitudePerNewton = 0.08;
  double MaximumAmplitude = 0.6;
  double IdleFrequency = 180.0;
  double FrequencyPerNewton = -12.0;
  double Phase = 0.0;
  double LastFrequency = 0.0;
  double LastAmplitude = 0.0;

private:
  vtkHapticVibration(const vtkHapticVibration&) = delete;
  void operator=(const vtkHapticVibration&) = delete;
};

#endif
