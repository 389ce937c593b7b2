"""Long work (a LUT bake, a world bake) off Blender's main thread, with progress and cancel.

``BackgroundTask(work)`` runs ``work(progress)`` in a thread; ``progress(fraction, text="")`` records how far
it is and raises ``Cancelled`` once ``cancel()`` was called, so the work stops at its next report and
leaves what it already wrote intact (the bakes write each group or file whole, or not at all).  The work
must not touch ``bpy``: read what it needs from Blender before, apply its result after (``finish``).

``ModalTask`` is the operator side: ``start_task(context, work, finish)`` shows the progress in the window
manager's progress bar and the status bar, Esc cancels, and ``finish(result)`` runs on the main thread
when the work is done.  Without a window (``blender --background``, tests) the work runs at once in the
calling thread and ``finish`` follows, so scripts get the same operator.
"""
from __future__ import annotations

import threading
import time

import bpy


class Cancelled(Exception):
    """The user cancelled the work (Esc)."""


class BackgroundTask:
    def __init__(self, work):
        self._work = work
        self._cancel = threading.Event()
        self._thread = None
        self.fraction = 0.0
        self.text = ""
        self.result = None
        self.error = None
        self.cancelled = False
        self.done = False
        self.started = None

    def progress(self, fraction, text=""):
        self.fraction = min(max(float(fraction), 0.0), 1.0)
        self.text = text
        if self._cancel.is_set():
            raise Cancelled()

    def _run(self):
        try:
            self.result = self._work(self.progress)
        except Cancelled:
            self.cancelled = True
        except Exception as ex:            # reported by the operator, on the main thread
            self.error = ex
        finally:
            self.done = True

    def start(self, thread=True):
        self.started = time.perf_counter()
        if thread:
            self._thread = threading.Thread(target=self._run, name="rt_lookdev task", daemon=True)
            self._thread.start()
        else:
            self._run()
        return self

    def cancel(self):
        self._cancel.set()

    def join(self, timeout=None):
        if self._thread is not None:
            self._thread.join(timeout)
        return self.done


class ModalTask:
    """Mixin of an operator whose ``execute`` calls ``self.start_task(context, work, finish)`` and returns
    its result.  ``finish(result) -> {'FINISHED'} | {'CANCELLED'}`` reports; it is not called when the work
    failed or was cancelled (the operator reports those)."""

    _timer = None
    _task = None
    _finish = None
    _label = "RT Lookdev"

    def start_task(self, context, work, finish):
        self._finish = finish
        window = context.window if not bpy.app.background else None
        self._task = BackgroundTask(work)
        if window is None:
            self._task.start(thread=False)
            return self._end(context)
        wm = context.window_manager
        self._task.start()
        wm.progress_begin(0, 1000)
        self._timer = wm.event_timer_add(0.1, window=window)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        task = self._task
        if event.type == 'ESC' and event.value == 'PRESS':
            task.cancel()
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        if not task.done:
            context.window_manager.progress_update(int(1000 * task.fraction))
            if context.workspace is not None:
                context.workspace.status_text_set(
                    f"{self._label}: {task.text or 'working'} ({100 * task.fraction:.0f}%), Esc to cancel")
            return {'RUNNING_MODAL'}
        return self._end(context)

    def _end(self, context):
        task = self._task
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
            wm.progress_end()
            if context.workspace is not None:
                context.workspace.status_text_set(None)
        seconds = time.perf_counter() - task.started
        if task.cancelled:
            self.report({'WARNING'}, f"{self._label}: cancelled after {seconds:.1f} s; nothing half-written was kept")
            return {'CANCELLED'}
        if task.error is not None:
            self.report({'ERROR'}, f"{self._label} failed: {type(task.error).__name__}: {task.error}")
            return {'CANCELLED'}
        return self._finish(task.result)
