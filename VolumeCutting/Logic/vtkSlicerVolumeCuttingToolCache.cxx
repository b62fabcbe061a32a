/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingToolCache.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutMeshTool.h"

// MRML includes
#include <vtkMRMLModelNode.h>

// VTK includes
#include <vtkObjectFactory.h>
#include <vtkPolyData.h>

// STD includes
#include <algorithm>

vtkStandardNewMacro(vtkSlicerVolumeCuttingToolCache);

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingToolCache::vtkSlicerVolumeCuttingToolCache() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingToolCache::~vtkSlicerVolumeCuttingToolCache() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingToolCache::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Tools: " << this->Tools.size() << "\n";
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingToolCache::Forget(const std::string& toolNodeId)
{
  this->Tools.erase(toolNodeId);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingToolCache::ForgetAll()
{
  this->Tools.clear();
}

//----------------------------------------------------------------------------
vtkVolumeCutTool* vtkSlicerVolumeCuttingToolCache::GetTool(vtkMRMLVolumeCutToolNode* toolNode)
{
  if (!toolNode || !toolNode->GetID() || toolNode->GetShape() == vtkMRMLVolumeCutToolNode::Sphere)
  {
    return nullptr;
  }
  vtkMTimeType time = toolNode->GetMTime();
  vtkMRMLModelNode* model = toolNode->GetMeshModelNode();
  if (model && model->GetPolyData())
  {
    time = std::max(time, model->GetPolyData()->GetMTime());
  }
  auto& cached = this->Tools[toolNode->GetID()];
  if (cached.second && cached.first == time)
  {
    return cached.second;
  }
  vtkSmartPointer<vtkVolumeCutTool> tool;
  switch (toolNode->GetShape())
  {
    case vtkMRMLVolumeCutToolNode::Cylinder:
    case vtkMRMLVolumeCutToolNode::DiskSaw:
    {
      auto cylinder = vtkSmartPointer<vtkVolumeCutCylinderTool>::New();
      cylinder->SetRadius(0.5 * toolNode->GetDiameter());
      // A disk saw is a cylinder as long as its blade is thick.
      cylinder->SetLength(toolNode->GetShape() == vtkMRMLVolumeCutToolNode::DiskSaw ? toolNode->GetThickness() : toolNode->GetLength());
      tool = cylinder;
      break;
    }
    case vtkMRMLVolumeCutToolNode::Blade:
    {
      auto box = vtkSmartPointer<vtkVolumeCutBoxTool>::New();
      box->SetSize(toolNode->GetWidth(), toolNode->GetThickness(), toolNode->GetLength());
      tool = box;
      break;
    }
    case vtkMRMLVolumeCutToolNode::Mesh:
    {
      if (!model || !model->GetPolyData() || model->GetPolyData()->GetNumberOfCells() == 0)
      {
        vtkErrorMacro("GetTool: the mesh tool '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' has no model with a surface");
        return nullptr;
      }
      auto mesh = vtkSmartPointer<vtkVolumeCutMeshTool>::New();
      mesh->SetSurface(model->GetPolyData());
      tool = mesh;
      break;
    }
    default:
      return nullptr;
  }
  if (!tool->IsValid())
  {
    vtkErrorMacro("GetTool: the tool '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' does not describe a valid tool");
    return nullptr;
  }
  cached = { time, tool };
  return tool;
}
