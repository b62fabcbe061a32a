// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticRecorder.h"
#include "vtkHapticDeviceCapabilities.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkHapticRecorder);

namespace
{
const char* const Magic = "# VolumeCutting haptic recording";
const int Version = 1;
const char* const Columns =
  "tick present x y z qw qx qy qz buttons switch fx fy fz px py pz drilling cut";
}

//------------------------------------------------------------------------------
vtkHapticRecorder::vtkHapticRecorder() = default;

//------------------------------------------------------------------------------
vtkHapticRecorder::~vtkHapticRecorder() = default;

//------------------------------------------------------------------------------
vtkHapticDeviceCapabilities* vtkHapticRecorder::GetCapabilities()
{
  return this->Capabilities;
}

//------------------------------------------------------------------------------
void vtkHapticRecorder::SetCapacity(int ticks)
{
  this->Ticks.assign(static_cast<size_t>(std::max(ticks, 0)), Tick{});
  this->Count.store(0, std::memory_order_release);
  this->Dropped.store(0, std::memory_order_relaxed);
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::Record(const Tick& tick)
{
  const int count = this->Count.load(std::memory_order_relaxed);
  if (count >= static_cast<int>(this->Ticks.size()))
  {
    this->Dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  this->Ticks[count] = tick;
  this->Count.store(count + 1, std::memory_order_release);
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::AppendInput(
  const double position[3], const double orientation[4], unsigned int buttons, unsigned int switchButtons, bool present)
{
  Tick tick{};
  tick.Index = static_cast<unsigned long long>(this->GetNumberOfTicks());
  tick.Present = present;
  std::copy(position, position + 3, tick.Position);
  std::copy(orientation, orientation + 4, tick.Orientation);
  tick.Buttons = buttons;
  tick.SwitchButtons = switchButtons;
  if (!this->Record(tick))
  {
    vtkErrorMacro("AppendInput: the recording is full (" << this->GetCapacity() << " ticks); raise its capacity first");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticRecorder::Clear()
{
  this->Count.store(0, std::memory_order_release);
  this->Dropped.store(0, std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickPresent(int n) const
{
  return n >= 0 && n < this->GetNumberOfTicks() && this->Ticks[n].Present;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickPosition(int n, double position[3]) const
{
  if (n < 0 || n >= this->GetNumberOfTicks())
  {
    return false;
  }
  std::copy(this->Ticks[n].Position, this->Ticks[n].Position + 3, position);
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickForce(int n, double force[3]) const
{
  if (n < 0 || n >= this->GetNumberOfTicks())
  {
    return false;
  }
  std::copy(this->Ticks[n].Force, this->Ticks[n].Force + 3, force);
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickProxy(int n, double position[3]) const
{
  if (n < 0 || n >= this->GetNumberOfTicks())
  {
    return false;
  }
  std::copy(this->Ticks[n].Proxy, this->Ticks[n].Proxy + 3, position);
  return true;
}

//------------------------------------------------------------------------------
unsigned int vtkHapticRecorder::GetTickButtons(int n) const
{
  return n >= 0 && n < this->GetNumberOfTicks() ? this->Ticks[n].Buttons | this->Ticks[n].SwitchButtons : 0u;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickDrilling(int n) const
{
  return n >= 0 && n < this->GetNumberOfTicks() && this->Ticks[n].Drilling;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::GetTickCut(int n) const
{
  return n >= 0 && n < this->GetNumberOfTicks() && this->Ticks[n].Cut;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::WriteFile(const char* fileName) const
{
  std::ofstream out(fileName ? fileName : "");
  if (!out)
  {
    vtkErrorMacro("WriteFile: cannot write the recording to '" << (fileName ? fileName : "") << "'");
    return false;
  }
  out << Magic << " " << Version << "\n";
  out << std::setprecision(17);
  out << "rate " << this->Rate << "\n";
  vtkHapticDeviceCapabilities* c = this->Capabilities;
  out << "device " << c->GetInputDegreesOfFreedom() << " " << c->GetForceDegreesOfFreedom() << " " << c->GetWorkspaceRadius() << " "
      << c->GetMaximumForce() << " " << c->GetMaximumStiffness() << " " << c->GetMaximumDamping() << " " << c->GetNumberOfButtons() << " "
      << c->GetUpdateRate() << "\n";
  out << "model " << c->GetModelName() << "\n";
  out << Columns << "\n";
  const int count = this->GetNumberOfTicks();
  for (int n = 0; n < count; ++n)
  {
    const Tick& t = this->Ticks[n];
    out << t.Index << " " << (t.Present ? 1 : 0);
    for (double v : t.Position)
    {
      out << " " << v;
    }
    for (double v : t.Orientation)
    {
      out << " " << v;
    }
    out << " " << t.Buttons << " " << t.SwitchButtons;
    for (double v : t.Force)
    {
      out << " " << v;
    }
    for (double v : t.Proxy)
    {
      out << " " << v;
    }
    out << " " << (t.Drilling ? 1 : 0) << " " << (t.Cut ? 1 : 0) << "\n";
  }
  out.flush();
  if (!out)
  {
    vtkErrorMacro("WriteFile: writing the recording to '" << fileName << "' failed (disk full?)");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticRecorder::ReadFile(const char* fileName)
{
  const std::string name = fileName ? fileName : "";
  std::ifstream in(name);
  if (!in)
  {
    vtkErrorMacro("ReadFile: cannot open the recording '" << name << "'");
    return false;
  }
  std::string line;
  int version = 0;
  if (!std::getline(in, line) || line.compare(0, std::string(Magic).size(), Magic) != 0 ||
    std::sscanf(line.c_str() + std::string(Magic).size(), "%d", &version) != 1 || version != Version)
  {
    vtkErrorMacro("ReadFile: '" << name << "' is not a VolumeCutting haptic recording of version " << Version);
    return false;
  }
  double rate = 0.0;
  int inputDOF = 0, forceDOF = 0, buttons = 0;
  double workspace = 0.0, maxForce = 0.0, maxStiffness = 0.0, maxDamping = 0.0, updateRate = 0.0;
  std::string model;
  int lineNumber = 1;
  auto fail = [&](const char* what) {
    vtkErrorMacro("ReadFile: '" << name << "', line " << lineNumber << ": " << what << "; nothing was read");
    return false;
  };
  if (!std::getline(in, line) || (++lineNumber, std::sscanf(line.c_str(), "rate %lf", &rate) != 1) || !(rate > 0.0))
  {
    return fail("expected 'rate <Hz>'");
  }
  if (!std::getline(in, line) || (++lineNumber, std::sscanf(line.c_str(), "device %d %d %lf %lf %lf %lf %d %lf", &inputDOF, &forceDOF, &workspace,
                                                  &maxForce, &maxStiffness, &maxDamping, &buttons, &updateRate) != 8))
  {
    return fail("expected the device's capabilities");
  }
  if (!std::getline(in, line) || (++lineNumber, line.compare(0, 6, "model ") != 0))
  {
    return fail("expected 'model <name>'");
  }
  model = line.substr(6);
  if (!std::getline(in, line) || (++lineNumber, line != Columns))
  {
    return fail("unexpected column names");
  }
  std::vector<Tick> ticks;
  while (std::getline(in, line))
  {
    ++lineNumber;
    if (line.empty())
    {
      continue;
    }
    std::istringstream fields(line);
    Tick t{};
    int present = 0, drilling = 0, cut = 0;
    fields >> t.Index >> present;
    for (double& v : t.Position)
    {
      fields >> v;
    }
    for (double& v : t.Orientation)
    {
      fields >> v;
    }
    fields >> t.Buttons >> t.SwitchButtons;
    for (double& v : t.Force)
    {
      fields >> v;
    }
    for (double& v : t.Proxy)
    {
      fields >> v;
    }
    fields >> drilling >> cut;
    std::string extra;
    if (!fields || (fields >> extra))
    {
      return fail("a tick must have 19 numbers");
    }
    t.Present = present != 0;
    t.Drilling = drilling != 0;
    t.Cut = cut != 0;
    ticks.push_back(t);
  }
  this->Ticks.swap(ticks);
  this->Count.store(static_cast<int>(this->Ticks.size()), std::memory_order_release);
  this->Dropped.store(0, std::memory_order_relaxed);
  this->Rate = rate;
  vtkHapticDeviceCapabilities* c = this->Capabilities;
  c->SetInputDegreesOfFreedom(inputDOF);
  c->SetForceDegreesOfFreedom(forceDOF);
  c->SetWorkspaceRadius(workspace);
  c->SetMaximumForce(maxForce);
  c->SetMaximumStiffness(maxStiffness);
  c->SetMaximumDamping(maxDamping);
  c->SetNumberOfButtons(buttons);
  c->SetUpdateRate(updateRate);
  c->SetModelName(model.c_str());
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticRecorder::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Capacity: " << this->GetCapacity() << "\n";
  os << indent << "NumberOfTicks: " << this->GetNumberOfTicks() << "\n";
  os << indent << "NumberOfDroppedTicks: " << this->GetNumberOfDroppedTicks() << "\n";
  os << indent << "Rate: " << this->Rate << " Hz\n";
}
