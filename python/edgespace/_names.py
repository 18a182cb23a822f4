"""The option vocabulary the command line and Python share (README
"Options"): one keyword per concept, the same name as the CLI's long option
(`where=` for --where, `components=` for --components, `pair_by=` for
--pair-by). A keyword spelt the old way still works, with one
DeprecationWarning naming the new one, so a notebook written for an older
release runs while it is being updated."""
import warnings


def renamed(where, new_name, new, old_name, old):
    """The value of keyword `new_name`, or of its old spelling `old_name`
    (warned about) when that was given instead; `where` names the call in
    messages. Both given is a TypeError: which one was meant is unknowable."""
    if old is None:
        return new
    if new is not None:
        raise TypeError(f"{where}: give {new_name}= (the new spelling of {old_name}=), "
                        "not both")
    warnings.warn(f"{where}: {old_name}= is now {new_name}=; the old spelling will go",
                  DeprecationWarning, stacklevel=3)
    return old
