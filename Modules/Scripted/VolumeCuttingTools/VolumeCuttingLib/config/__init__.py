"""Tool and device configuration without Qt, shared by the desktop widgets and the web application.

``toolconfig`` holds the cutting-tool parameters, presets, sensibility table
and device choice; ``inputdevices`` lists the mouse and the known haptic, 6-DoF
and foot-switch devices plugged in (standard library only); ``hapticdrilling``
drills with the device chosen. Builds on ``scene`` only.
"""
