"""focsim's CSV as the monitor's end-to-end tests read it: columns of
strings (their decimals tell the resolution the CSV printed)."""


def decimals(s):
    """Digits after the decimal point in a CSV field."""
    return len(s.split(".", 1)[1]) if "." in s else 0


def read_csv(path):
    """{column name: [field, ...]} of a focsim CSV."""
    with open(path) as f:
        names = f.readline().strip().split(",")
        cols = {n: [] for n in names}
        for line in f:
            for n, v in zip(names, line.strip().split(",")):
                cols[n].append(v)
    return cols
