"""Cutting sessions run from Python through the module logic.

``drilling`` plans scripted drilling paths (a cortical mastoidectomy),
``recording`` saves and replays the pose streams of recorded sessions, and
``softcut`` drives SoftCut resection planning and draws outlines as a user
would. Builds on ``scene`` and ``data``.
"""
