"""python3 -m birkhoff_cart_study STUDY.yaml ...: the study runner (cli.py; docs/studies.md)."""
import sys

from birkhoff_cart_study.cli import main

if __name__ == "__main__":
    sys.exit(main())
