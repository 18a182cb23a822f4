"""The text of a PDF as cairo writes it, read with zlib and the fonts'
ToUnicode maps (no PDF library, so it is independent of the one that wrote
the file): each shown string's codes mapped through the map of the font
selected by the last Tf before it."""
import re
import zlib


def _streams(data):
    """{object number: decompressed stream} of the Flate streams."""
    out = {}
    for m in re.finditer(rb"(\d+) 0 obj\s*<<(.*?)>>\s*stream\r?\n(.*?)\r?\nendstream", data, re.S):
        try:
            out[int(m.group(1))] = zlib.decompress(m.group(3))
        except zlib.error:
            continue
    return out


def _cmap(text):
    """code -> unicode string of one ToUnicode CMap (bfchar and bfrange),
    and the bytes per code (its codespacerange)."""
    table = {}
    space = re.search(rb"begincodespacerange\s*<([0-9a-fA-F]+)>", text)
    width = len(space.group(1)) // 2 if space else 1
    for block in re.findall(rb"beginbfchar(.*?)endbfchar", text, re.S):
        for src, dst in re.findall(rb"<([0-9a-fA-F]+)>\s*<([0-9a-fA-F]+)>", block):
            table[int(src, 16)] = bytes.fromhex(dst.decode()).decode("utf-16-be")
    for block in re.findall(rb"beginbfrange(.*?)endbfrange", text, re.S):
        for lo, hi, dst in re.findall(rb"<([0-9a-fA-F]+)>\s*<([0-9a-fA-F]+)>\s*<([0-9a-fA-F]+)>",
                                      block):
            base = bytes.fromhex(dst.decode()).decode("utf-16-be")
            for k, code in enumerate(range(int(lo, 16), int(hi, 16) + 1)):
                table[code] = base[:-1] + chr(ord(base[-1]) + k)
    return table, width


def _literal(s):
    """The bytes of a PDF literal string body (escapes resolved)."""
    out, i = bytearray(), 0
    while i < len(s):
        c = s[i]
        if c == 0x5C and i + 1 < len(s):   # backslash
            n = s[i + 1]
            if 0x30 <= n <= 0x37:
                j = i + 1
                while j < len(s) and j < i + 4 and 0x30 <= s[j] <= 0x37:
                    j += 1
                out.append(int(s[i + 1:j], 8) & 0xFF)
                i = j
                continue
            out.append({0x6E: 10, 0x72: 13, 0x74: 9, 0x62: 8, 0x66: 12}.get(n, n))
            i += 2
            continue
        out.append(c)
        i += 1
    return bytes(out)


_TOKENS = re.compile(rb"/([\w.+-]+)\s+[\d.]+\s+Tf|\((?:\\.|[^\\)])*\)|<[0-9a-fA-F]*>|"
                     rb"\b(Tj|TJ|Tm|Td|TD|T\*|ET)\b")


def _decode(codes, cmap):
    table, width = cmap
    return "".join(table.get(int.from_bytes(codes[i:i + width], "big"), "\ufffd")
                   for i in range(0, len(codes), width))


def pdf_strings(path):
    """Every run of text the PDF shows, decoded, in content-stream order: the
    strings shown one after another without a move between them (cairo
    switches fonts inside a word for a character like "≥") are one run."""
    data = open(path, "rb").read()
    streams = _streams(data)
    fonts = {}   # resource name -> (cmap, bytes per code)
    for name, obj in re.findall(rb"/([\w.+-]+)\s+(\d+)\s+0\s+R", data):
        m = re.search(rb"\b" + obj + rb" 0 obj\s*<<(.*?)>>\s*endobj", data, re.S)
        if m and b"/ToUnicode" in m.group(1):
            tu = int(re.search(rb"/ToUnicode\s+(\d+)", m.group(1)).group(1))
            if tu in streams:
                fonts[name.decode()] = _cmap(streams[tu])
    out = []
    for text in streams.values():
        if b"BT" not in text:
            continue
        cmap, pending, run = ({}, 1), [], ""
        for m in _TOKENS.finditer(text):
            tok, op = m.group(0), m.group(2)
            if m.group(1):
                cmap = fonts.get(m.group(1).decode(), ({}, 1))
            elif tok.startswith(b"("):
                pending.append(_literal(tok[1:-1]))
            elif tok.startswith(b"<"):
                pending.append(bytes.fromhex(tok[1:-1].decode()))
            elif op in (b"Tj", b"TJ"):
                run += "".join(_decode(p, cmap) for p in pending)
                pending = []
            elif op:   # a move or the end of the text object ends the run
                if run:
                    out.append(run)
                run = ""
        if run:
            out.append(run)
    return out


def pdf_codepoints(path):
    """Every unicode character any font of the PDF maps a code to."""
    data = open(path, "rb").read()
    chars = set()
    for text in _streams(data).values():
        if b"beginbfchar" in text or b"beginbfrange" in text:
            chars.update("".join(_cmap(text)[0].values()))
    return chars
