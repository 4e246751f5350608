"""navlib: simulators and error-compensation algorithms behind the navbook replication book."""
__version__ = "0.1.0"
