"""Python helpers of the VolumeCutting extension.

Modules:
    phantom: procedural temporal-bone CT phantom with analytic geometry.
    headct: loader for the real head CT shipped by Debian (invesalius-examples).
    nodes: numpy <-> MRML volume helpers shared by the two.
    application: a scene with Slicer's logics and an offscreen 3D view, without Qt.
    drilling: scripted drilling paths (cortical mastoidectomy) replayed through the logic.
    owndata: the user's own CT (DICOM series, NRRD, NIfTI, MetaImage) and segmentation (.seg.nrrd or
        labelmap with a colour table) through Slicer's storage nodes; roles by segment name; InputError.
    dicomseries: write a scalar volume as a DICOM CT series (pydicom), any IJK-to-RAS.
    patientscale: the patient-scale test case (512 x 512 x 133 CT from the head CT, long segments), cached.
    mainjob: the README's main job.
    benchmarks: the benchmark harness (one JSON per area).
    analyticscene: the mapper's accuracy scene (a cut cube) and its exact ray tracing and metrics.
    mapperbenchmarks: the ``mapper`` benchmark area (accuracy and frame times vs VTK's stock mapper).
    slicebenchmarks: the ``sliceview`` benchmark area (cut overlay on slice views after a stroke).
    workflowbenchmarks: the ``workflow`` benchmark area (first stroke, role change, shield memory,
        live tables and reload on the patient-scale case, one core).
    toolconfig: cutting-tool parameters, presets, sensibility table and device choice, without Qt
        (shared by the desktop module and a web application).
    inputdevices: the mouse and the known haptic, 6-DoF and foot-switch devices plugged in
        (hidapi and libusb through ctypes; standard library only).

Submodules are not imported here so that the numpy-only parts stay usable
without VTK or Slicer.
"""
