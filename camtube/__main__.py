import sys

from camtube.cli import main

sys.exit(main())
