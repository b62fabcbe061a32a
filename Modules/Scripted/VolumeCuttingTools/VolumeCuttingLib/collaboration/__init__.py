"""Instructor and trainee together: live bridges out of a drilling session.

Between ``assessment`` and ``jobs``: the OpenIGTLink bridge to desktop Slicer
and the settings of forwarded forces read the logic and the feedback layer,
and the main job and the web application start them. Neither Slicer's GUI
nor Qt is needed.
"""
