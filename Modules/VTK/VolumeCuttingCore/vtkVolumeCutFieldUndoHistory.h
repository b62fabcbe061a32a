// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutFieldUndoHistory
 * @brief   The strokes of a vtkVolumeCutField that can be undone and redone.
 *
 * Private to VolumeCuttingCore (not installed, not wrapped). The field's
 * writer tells it which bricks a stroke is about to change; the history keeps
 * each such brick's values from before the stroke, once per stroke, and on
 * Undo or Redo writes them back through the field's brick store. It keeps its
 * memory within the field's UndoMemoryBudget by dropping the oldest steps.
 *
 * Threads: the field's writer thread only, as every method of the field that
 * changes it.
 */
#ifndef vtkVolumeCutFieldUndoHistory_h
#define vtkVolumeCutFieldUndoHistory_h

#include "vtkObject.h"
#include "vtkVolumeCutFieldInternals.h" // For vtkVolumeCutField::Brick

#include <cstddef> // For size_t
#include <vector>  // For the steps

class vtkVolumeCutFieldUndoHistory : public vtkObject
{
public:
  static vtkVolumeCutFieldUndoHistory* New();
  vtkTypeMacro(vtkVolumeCutFieldUndoHistory, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  using BrickValues = vtkVolumeCutField::BrickValues;
  using BrickStates = vtkVolumeCutField::BrickStates;

  /// The field whose bricks the history reads and writes back, and whose
  /// name its messages carry. Not reference counted: the field owns the history.
  void SetField(vtkVolumeCutField* field) { this->Field = field; }

  ///@{
  /// A stroke groups the changes between BeginStroke and EndStroke into one step.
  void BeginStroke();
  void EndStroke();
  bool IsStrokeOpen() const { return this->StrokeOpen; }
  ///@}

  /// Counts the strokes begun: a brick remembered in the open one carries its number.
  vtkTypeUInt64 GetStrokeSerial() const { return this->StrokeSerial; }

  /**
   * Keep the brick's values (brick: null where it does not exist yet) before
   * the open stroke first changes it. Cheap for a brick the stroke has
   * remembered already, which is the common case on the writer's hot path.
   */
  void RememberBrickBeforeChange(vtkIdType brickId, const vtkVolumeCutField::Brick* brick)
  {
    if (brick && brick->RememberedInStroke == this->StrokeSerial)
    {
      return;
    }
    this->RememberBrick(brickId, brick);
  }

  ///@{
  /// Undo or redo one step (an open stroke is ended first); false and an
  /// error when there is none.
  bool Undo();
  bool Redo();
  ///@}

  int GetNumberOfUndoSteps() const { return static_cast<int>(this->UndoStack.size()); }
  int GetNumberOfRedoSteps() const { return static_cast<int>(this->RedoStack.size()); }
  /// Bytes the undo steps hold.
  size_t GetMemorySize() const { return this->UndoMemorySize; }

  /// Forget every step and the open stroke (which is closed without a step).
  void Clear();

protected:
  vtkVolumeCutFieldUndoHistory();
  ~vtkVolumeCutFieldUndoHistory() override;

  /// One stroke's bricks as they were before it (empty values: the brick did
  /// not exist, all Outside). The state after it is read back when the stroke
  /// is undone (until then the field holds it: every later change is a later
  /// step, undone first, or clears the history), so closing a stroke copies
  /// nothing; steps waiting to be redone hold both.
  struct Step
  {
    BrickStates Before;
    BrickStates After;
    size_t Memory = 0; // bytes held, kept by whoever changes Before or After

    static size_t EntryMemory(const BrickValues& values) { return values.size() * sizeof(int16_t) + 64; }
    size_t MemorySize() const { return this->Memory; }
    void CountMemory();
  };

  void RememberBrick(vtkIdType brickId, const vtkVolumeCutField::Brick* brick);
  void PushUndoStep(Step&& step);

  vtkVolumeCutField* Field = nullptr;
  bool StrokeOpen = false;
  vtkTypeUInt64 StrokeSerial = 0;
  // Bricks touched by the open stroke: their values before it began.
  BrickStates StrokeBefore;
  size_t StrokeBeforeMemory = 0;
  std::vector<Step> UndoStack;
  std::vector<Step> RedoStack;
  size_t UndoMemorySize = 0;

private:
  vtkVolumeCutFieldUndoHistory(const vtkVolumeCutFieldUndoHistory&) = delete;
  void operator=(const vtkVolumeCutFieldUndoHistory&) = delete;
};

#endif
