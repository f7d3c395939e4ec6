"""The package version, in a module of its own: the run folder and the runner's headers
read it without importing the package's ``__init__`` (which lazily re-exports the
application, so importing it from the application would be an import cycle), and
``pyproject.toml`` takes it from here."""
__version__ = "0.1.0"
