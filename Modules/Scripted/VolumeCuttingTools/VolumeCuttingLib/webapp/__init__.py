"""The web application: drilling in the browser with trame-slicer (``Utilities/vc app``).

Modules:
    session: one user's session (data, roles, tool, strokes, tables, exports), without a web server.
    views: trame-slicer views with the product's displayable managers; the drill pipeline and tool glyph.
    app: the trame application (page, panels, uploads, downloads, tabs and connections).

Submodules are imported on use: trame-slicer is only needed by ``views`` and ``app``.
"""
