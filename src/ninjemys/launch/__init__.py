"""roslaunch: XML + substitutions -> a plain-data plan (``xml``, ``plan``) -> supervised processes (``runner``)."""
