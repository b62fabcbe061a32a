// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutTextureUtilities.h"

#include <vtkAbstractArray.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkTextureObject.h>
#include <vtk_glad.h>

#include <algorithm>

//------------------------------------------------------------------------------
vtkSmartPointer<vtkTextureObject> vtkVolumeCutTextureUtilities::Texture3D(
  vtkOpenGLRenderWindow* window, int x, int y, int z, int components, const float* data)
{
  return Texture3D(window, x, y, z, components, VTK_FLOAT, 0, data);
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkTextureObject> vtkVolumeCutTextureUtilities::Texture3D(vtkOpenGLRenderWindow* window, int x, int y, int z,
  int components, int vtkType, unsigned int internalFormat, const void* data)
{
  auto texture = vtkSmartPointer<vtkTextureObject>::New();
  texture->SetContext(window);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
  texture->SetWrapR(vtkTextureObject::ClampToEdge);
  texture->SetMinificationFilter(vtkTextureObject::Nearest);
  texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  if (internalFormat != 0)
  {
    texture->SetInternalFormat(internalFormat);
    texture->SetFormat(components == 4 ? GL_RGBA : GL_RED);
  }
  if (!texture->Create3DFromRaw(x, y, z, components, vtkType, const_cast<void*>(data)))
  {
    return nullptr;
  }
  return texture;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkTextureObject> vtkVolumeCutTextureUtilities::Texture2D(
  vtkOpenGLRenderWindow* window, int x, int y, int components, const float* data)
{
  auto texture = vtkSmartPointer<vtkTextureObject>::New();
  texture->SetContext(window);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
  texture->SetMinificationFilter(vtkTextureObject::Nearest);
  texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  if (!texture->Create2DFromRaw(x, y, components, VTK_FLOAT, const_cast<float*>(data)))
  {
    return nullptr;
  }
  return texture;
}

//------------------------------------------------------------------------------
void vtkVolumeCutTextureUtilities::SetLinearFiltering(vtkTextureObject* texture, bool linear)
{
  const int filter = linear ? vtkTextureObject::Linear : vtkTextureObject::Nearest;
  texture->SetMinificationFilter(filter);
  texture->SetMagnificationFilter(filter);
}

//------------------------------------------------------------------------------
int vtkVolumeCutTextureUtilities::BytesPerVoxel(vtkTextureObject* texture)
{
  GLint bits = 0;
  texture->Activate();
  glGetTexLevelParameteriv(GL_TEXTURE_3D, 0, GL_TEXTURE_RED_SIZE, &bits);
  texture->Deactivate();
  return bits / 8;
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutTextureUtilities::MemorySize(vtkTextureObject* texture)
{
  if (!texture)
  {
    return 0;
  }
  // The size of the uploaded type is the size of each texture's format.
  return static_cast<size_t>(texture->GetWidth()) * texture->GetHeight() * std::max(1u, texture->GetDepth()) *
    texture->GetComponents() * vtkAbstractArray::GetDataTypeSize(texture->GetVTKDataType());
}

//------------------------------------------------------------------------------
void vtkVolumeCutTextureUtilities::Release(vtkTextureObject* texture, vtkWindow* window)
{
  if (texture)
  {
    texture->ReleaseGraphicsResources(window);
  }
}
