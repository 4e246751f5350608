"""nbval settings for the stored notebooks: stderr (kernel warnings, tqdm bars) is not compared."""


def pytest_collectstart(collector):
    if collector.fspath and collector.fspath.ext == ".ipynb":
        collector.skip_compare += ("stderr", "application/javascript", "text/html")
