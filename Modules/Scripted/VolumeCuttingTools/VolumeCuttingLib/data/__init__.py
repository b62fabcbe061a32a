"""The data sets drilled and measured on, and the user's own data.

``headct`` (Debian's real head CT), ``phantom`` (the procedural temporal-bone
phantom), ``softcutphantom`` (skin over a bone shell, for SoftCut),
``patientscale`` (a chest-CT-sized case made from the head CT),
``analyticscene`` and ``labelsurfaces`` (analytic scenes with exact references
for the renderers' accuracy), ``owndata`` and ``dicomseries`` (a clinician's CT
and segmentation in, a DICOM series out). Builds on ``scene`` only.
"""
