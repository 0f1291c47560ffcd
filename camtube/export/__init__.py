"""Export stage: pure writers from contours and jobs to DXF, G-code, job files.

Writers return ``str``/``bytes`` or a document object; :mod:`camtube.io`
writes files atomically. The wrap from the unrolled frame to a rotary axis
happens only in the post-processor.
"""
