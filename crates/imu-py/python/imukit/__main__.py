"""``python -m imukit …`` runs the ``imukit`` command line (the same as the ``imukit`` command)."""
from _imukit_cli import main

if __name__ == "__main__":
    main()
