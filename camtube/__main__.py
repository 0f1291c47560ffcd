import sys

from camtube.commands import main

sys.exit(main())
