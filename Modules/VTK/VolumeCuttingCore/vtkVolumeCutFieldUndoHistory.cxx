// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutFieldUndoHistory.h"

#include "vtkObjectFactory.h"

#include <utility>

vtkStandardNewMacro(vtkVolumeCutFieldUndoHistory);

using vtkVolumeCutFieldInternals::SamplesPerBrick;

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::Step::CountMemory()
{
  this->Memory = 0;
  for (const BrickStates* states : { &this->Before, &this->After })
  {
    for (const auto& entry : *states)
    {
      this->Memory += EntryMemory(entry.second);
    }
  }
}

//------------------------------------------------------------------------------
vtkVolumeCutFieldUndoHistory::vtkVolumeCutFieldUndoHistory() = default;

//------------------------------------------------------------------------------
vtkVolumeCutFieldUndoHistory::~vtkVolumeCutFieldUndoHistory() = default;

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "StrokeOpen: " << this->StrokeOpen << "\n";
  os << indent << "UndoSteps: " << this->UndoStack.size() << " (" << this->UndoMemorySize / 1024 << " KiB)\n";
  os << indent << "RedoSteps: " << this->RedoStack.size() << "\n";
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::Clear()
{
  this->UndoStack.clear();
  this->RedoStack.clear();
  this->UndoMemorySize = 0;
  this->StrokeOpen = false;
  this->StrokeBefore.clear();
  this->StrokeBeforeMemory = 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::RememberBrick(vtkIdType brickId, const vtkVolumeCutField::Brick* brick)
{
  // A brick that did not exist is remembered empty (all Outside): a moving
  // burr enters new bricks every few segments, and the haptic thread should
  // not fill kilobytes of Outside for each.
  const auto inserted = this->StrokeBefore.try_emplace(brickId);
  if (!inserted.second)
  {
    return;
  }
  BrickValues& values = inserted.first->second;
  if (brick)
  {
    values.resize(SamplesPerBrick);
    for (int index = 0; index < SamplesPerBrick; ++index)
    {
      values[index] = brick->Values[index].load(std::memory_order_relaxed);
    }
  }
  this->StrokeBeforeMemory += Step::EntryMemory(values);
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::BeginStroke()
{
  if (this->StrokeOpen)
  {
    return;
  }
  this->StrokeOpen = true;
  ++this->StrokeSerial;
  this->StrokeBefore.clear();
  this->StrokeBeforeMemory = 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::EndStroke()
{
  if (!this->StrokeOpen)
  {
    return;
  }
  this->StrokeOpen = false;
  if (this->StrokeBefore.empty())
  {
    return;
  }
  // Handed over whole, copying nothing: the haptic thread may close strokes.
  Step step;
  step.Before.swap(this->StrokeBefore);
  step.Memory = this->StrokeBeforeMemory;
  this->StrokeBeforeMemory = 0;
  this->RedoStack.clear();
  this->PushUndoStep(std::move(step));
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldUndoHistory::PushUndoStep(Step&& step)
{
  const size_t budget = this->Field->GetUndoMemoryBudget();
  const size_t stepSize = step.MemorySize();
  if (stepSize > budget)
  {
    vtkErrorWithObjectMacro(this->Field, "EndStroke: this stroke changed " << stepSize / 1024 << " KiB of the cut field, more than the undo budget of "
                                                                          << budget / 1024 << " KiB; it cannot be undone, and older steps are dropped");
    this->UndoStack.clear();
    this->UndoMemorySize = 0;
    return;
  }
  int dropped = 0;
  while (!this->UndoStack.empty() && this->UndoMemorySize + stepSize > budget)
  {
    this->UndoMemorySize -= this->UndoStack.front().MemorySize();
    this->UndoStack.erase(this->UndoStack.begin());
    ++dropped;
  }
  if (dropped > 0)
  {
    vtkWarningWithObjectMacro(this->Field, "EndStroke: the undo history reached its budget of " << budget / 1024 << " KiB; the oldest " << dropped
                                                                                               << " step(s) can no longer be undone");
  }
  this->UndoMemorySize += stepSize;
  this->UndoStack.push_back(std::move(step));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFieldUndoHistory::Undo()
{
  this->EndStroke();
  if (this->UndoStack.empty())
  {
    vtkErrorWithObjectMacro(this->Field, "Undo: there is no stroke to undo");
    return false;
  }
  Step step = std::move(this->UndoStack.back());
  this->UndoStack.pop_back();
  this->UndoMemorySize -= step.MemorySize();
  // The field holds the state after this step: keep it for a redo.
  step.After.clear();
  for (const auto& entry : step.Before)
  {
    BrickValues& after = step.After[entry.first];
    after.resize(SamplesPerBrick);
    this->Field->CopyBrick(entry.first, after.data());
  }
  step.CountMemory();
  this->Field->WriteBricks(step.Before);
  this->RedoStack.push_back(std::move(step));
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFieldUndoHistory::Redo()
{
  this->EndStroke();
  if (this->RedoStack.empty())
  {
    vtkErrorWithObjectMacro(this->Field, "Redo: there is no stroke to redo");
    return false;
  }
  Step step = std::move(this->RedoStack.back());
  this->RedoStack.pop_back();
  this->Field->WriteBricks(step.After);
  step.After.clear(); // read back again by the next undo
  step.CountMemory();
  this->UndoMemorySize += step.MemorySize();
  this->UndoStack.push_back(std::move(step));
  return true;
}
