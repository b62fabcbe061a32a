// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticDeviceCapabilities.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkHapticDeviceCapabilities);

//------------------------------------------------------------------------------
void vtkHapticDeviceCapabilities::DeepCopy(vtkHapticDeviceCapabilities* source)
{
  if (!source)
  {
    return;
  }
  this->ModelName = source->ModelName;
  this->Manufacturer = source->Manufacturer;
  this->InputDegreesOfFreedom = source->InputDegreesOfFreedom;
  this->ForceDegreesOfFreedom = source->ForceDegreesOfFreedom;
  this->WorkspaceRadius = source->WorkspaceRadius;
  this->MaximumForce = source->MaximumForce;
  this->MaximumStiffness = source->MaximumStiffness;
  this->MaximumDamping = source->MaximumDamping;
  this->NumberOfButtons = source->NumberOfButtons;
  this->UpdateRate = source->UpdateRate;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkHapticDeviceCapabilities::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ModelName: " << this->ModelName << "\n";
  os << indent << "Manufacturer: " << this->Manufacturer << "\n";
  os << indent << "InputDegreesOfFreedom: " << this->InputDegreesOfFreedom << "\n";
  os << indent << "ForceDegreesOfFreedom: " << this->ForceDegreesOfFreedom << "\n";
  os << indent << "WorkspaceRadius: " << this->WorkspaceRadius << " mm\n";
  os << indent << "MaximumForce: " << this->MaximumForce << " N\n";
  os << indent << "MaximumStiffness: " << this->MaximumStiffness << " N/mm\n";
  os << indent << "MaximumDamping: " << this->MaximumDamping << " N s/mm\n";
  os << indent << "NumberOfButtons: " << this->NumberOfButtons << "\n";
  os << indent << "UpdateRate: " << this->UpdateRate << " Hz\n";
}
