"""Reports: fit tables and JSON (:mod:`.fit`), fit figures (:mod:`.plot`), the diagnosis in text, JSON
and HTML (:mod:`.diagnosis`). Pure writers return ``str``/``bytes``; :mod:`camtube.io` writes files."""
