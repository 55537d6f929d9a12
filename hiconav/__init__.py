"""hiconav: deployable hierarchical vision-language object navigation."""
__version__ = "0.1.0"
