import os
import sys

# Test the installed package, never the sources in python/.
_src = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != _src]
