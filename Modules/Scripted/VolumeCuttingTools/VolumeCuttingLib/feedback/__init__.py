"""What the trainee hears and is warned of while drilling (seed 003).

The drill sound and the nerve monitor's readings, computed from the tool,
the cut field and the protected structures. Builds on ``scene`` to
``cutting``; the jobs and the web application play and show it.
"""
